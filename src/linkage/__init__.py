"""linkage: position analysis of planar mechanisms by numerical root finding.

The public API, in the order a reader meets it:

- :func:`solve_scalar` solves one equation in one unknown with a named method and
  returns a :class:`Result` (status, root, iterations, evaluations, history).
- :func:`fourbar_equation` and :func:`equation_problem` build the problems it solves.
- :func:`solve_system` solves loop-closure systems; :func:`load_mechanism` reads a
  mechanism file whose ``.problem()`` it takes.
- :func:`analyze` estimates convergence order and rate from a recorded history.
"""

from .analysis.convergence import Convergence, analyze
from .errors import InputError, LinkageError, NotConvergedError, ParseError
from .problems.expression import equation_problem
from .problems.freudenstein import coefficients_from_links, fourbar_equation
from .problems.loops import Mechanism
from .problems.loops import load as load_mechanism
from .problems.scalar import ScalarProblem
from .problems.system import SystemProblem
from .result import History, IterationRecord, Result, Status
from .solve import solve_scalar, solve_system

__version__ = "0.1.0"

__all__ = [
    "Convergence",
    "History",
    "InputError",
    "IterationRecord",
    "LinkageError",
    "Mechanism",
    "NotConvergedError",
    "ParseError",
    "Result",
    "ScalarProblem",
    "Status",
    "SystemProblem",
    "analyze",
    "coefficients_from_links",
    "equation_problem",
    "fourbar_equation",
    "load_mechanism",
    "solve_scalar",
    "solve_system",
]
