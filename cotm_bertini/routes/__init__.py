"""How one parameter set is solved: the routes, what each proves, and the one function that
chooses among them (`choose`, routes/choice.py).

- real (routes/real.py): a branch and bound over the configuration space in interval
  arithmetic (boxsearch): every real equilibrium, proved complete where the search decides
  every box; the default for every framework whose configuration space it covers.
- homotopy (routes/homotopy.py): Bertini 2 in-process, a parameter homotopy from a cached
  generic solution set (built by monodromy or by a total-degree homotopy: backends.generic
  chooses per set from its path count): every complex root, of the paper's system or of each
  taut set of a framework; complete where the generic set is.
- command (routes/command.py): the `bertini2` command or a user's Bertini 1.x binary on the
  paper's system, in a run folder: every complex root of a total-degree or user-set homotopy.

Each returns a routes.result.PointSolution: the classified rows, counts, checks and status.
"""

from .choice import PROVES, Choice, choose

__all__ = ["PROVES", "Choice", "choose"]
