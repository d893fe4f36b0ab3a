"""What ``linkage bench`` and ``linkage stress`` measure: speed as ratios against hand-written
baselines (:mod:`.hand`) timed in the same run (:mod:`.timing`), issue 33's targets
(:mod:`.targets`), issue 34's absolute times with their roots checked at 50 digits
(:mod:`.continuation_targets`), the earlier ones (:mod:`.sweeps`), work precision (:mod:`.precision`),
fresh processes (:mod:`.processes`), and the stress battery (:mod:`.stress`,
:mod:`.stress_cases`, :mod:`.mgh_table`)."""
