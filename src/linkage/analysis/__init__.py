"""Post-processing over results: convergence order and rates."""
