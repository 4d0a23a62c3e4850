"""The one place a route is chosen (`choose`) and a setting no route would honour is refused
(`check_route`), for the paper's mechanism and for frameworks alike."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import ParameterError
from ..model.framework.structure import layout as model_layout
from ..params import Params
from ..settings import Settings

# What each route proves (routes/__init__.py), as the cost statement and the docs say it.
PROVES = {
    "real": "a branch and bound over its configuration space in interval arithmetic: every real "
    "equilibrium, proved complete where every box is decided",
    "homotopy": "Bertini 2 in-process, a parameter homotopy from a cached generic set: every "
    "complex root of every taut set, complete where the generic set is (trace test, or two "
    "seeds that agree)",
    "command": "the bertini2 command or a Bertini 1.x binary: every complex root its homotopy "
    "reaches, checked by its path counts and the Morse count",
}


@dataclass(frozen=True)
class Choice:
    """A route ("real", "homotopy" or "command": routes/__init__.py) and why it was taken."""

    route: str
    why: str

    @property
    def real(self) -> bool:
        """Whether it is the real route."""
        return self.route == "real"

    @property
    def proves(self) -> str:
        """What the route finds and proves (PROVES)."""
        return PROVES[self.route]


def check_route(model, settings: Settings, what: str = "solve") -> None:
    """Refuse a route the model cannot take, a setting it would not honour, or local workers
    where nothing would use them, before any work or folder (ParameterError). `what`: "solve",
    or one of PAPER_BERTINI_ONLY (a sweep or map solves each point in one process and splits
    its points over its own workers)."""
    workers = settings.workers not in (None, 1)
    if what != "solve" and settings.workers is not None:
        raise ParameterError(
            f"workers = {settings.workers!r} in the settings: a sweep or map solves each point "
            "in one process and splits its points over its own workers (workers=, --workers)"
        )
    if settings.only != "all" and (isinstance(model, Params) or not choose(model, settings).real):
        name = "the paper's mechanism" if isinstance(model, Params) else model.name
        raise ParameterError(
            f"only = {settings.only!r}: a search of the real route's alone; {name} is solved "
            "on the complex route, every critical point (its stable rows: result.stable)"
        )
    if not isinstance(model, Params):
        if settings.only != "all" and model.dim == 2 and model_layout(model).closing_pins:
            raise ParameterError(
                f"only = {settings.only!r}: not yet for a closed loop ({model.name}): its "
                "search is for every critical point on the loop (the stable rows: "
                "result.stable)"
            )
        if not choose(model, settings).real and workers:
            raise ParameterError(
                f"workers = {settings.workers!r}: local workers share the real route's boxes; "
                f"the complex route of {model.name} is not split over them (a scheduler splits "
                "its generic sets' paths)"
            )
        return
    if workers:
        raise ParameterError(
            f"workers = {settings.workers!r}: the paper's mechanism is solved in one process "
            "(threads= sets Bertini's threads)"
        )
    if settings.route == "real":
        if what in PAPER_BERTINI_ONLY:
            raise ParameterError(
                f"route = 'real': {what} of the paper's mechanism is by Bertini only "
                f"({PAPER_BERTINI_ONLY[what]}); solve one point with route='real', or use "
                "examples/cotm.toml, the same mechanism as a framework"
            )
        for name in PAPER_REAL_REFUSED:
            if getattr(settings, name) != getattr(Settings(engine="homotopy"), name):
                raise ParameterError(
                    f"{name} = {getattr(settings, name)!r} with route = 'real': the real route "
                    "runs no Bertini (a branch and bound over the angles, in this process)"
                )


# What the paper's mechanism does on Bertini's complex roots only, and why.
PAPER_BERTINI_ONLY = {
    "sweep": "its continuation and events follow complex roots: a real sweep loses its folds",
    "map": "its fold curves and regions follow complex roots",
    "verify": "it compares every complex root with the resultant's and PHCpack's",
}

# Settings that only reach Bertini: the real route cannot honour them (`timeout` it does; it
# runs in one thread, so `threads` is kept as a bound, as a sweep's workers set it).
PAPER_REAL_REFUSED = (
    "engine", "mptype", "precision", "final_tol", "tracktol_before_eg", "tracktol_during_eg",
    "security_level", "condnum_threshold", "max_norm", "bertini", "extra_config",
    "variable_groups", "scheduler",
)  # fmt: skip


def choose(model, settings: Settings) -> Choice:
    """The route that solves `model` (cb.Params: the paper's mechanism, or a cb.Framework) under
    `settings`, and why: the one asked for (route=, engine=), else the real route wherever it
    covers the configuration space (boxsearch.real_route.covers), else the homotopy. A refusal
    (ParameterError) names why route='real' cannot be taken."""
    if isinstance(model, Params):
        if settings.route == "real":
            return Choice("real", "route = 'real' asked for")
        if settings.engine == "homotopy":
            return Choice("homotopy", "the paper's mechanism: a parameter homotopy from its "
                          "cached generic set")  # fmt: skip
        return Choice("command", f"engine = {settings.engine!r} asked for")
    from ..boxsearch.real_route import covers

    why = covers(model)
    if settings.route == "real" and why:
        raise ParameterError(
            f"route = 'real': not yet for {model.name}: {why}; use route='complex'"
        )
    if settings.route is not None:
        return Choice("real" if settings.route == "real" else "homotopy",
                      f"route = {settings.route!r} asked for")  # fmt: skip
    if why:
        return Choice("homotopy", f"the real route does not cover it: {why}")
    if settings.generic:
        return Choice("homotopy", f"generic = {settings.generic!r} asked for (a generic set "
                      "is the homotopy's)")  # fmt: skip
    return Choice("real", "the default where the real route covers the configuration space")
