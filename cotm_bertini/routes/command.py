"""The command route: the `bertini2` command or a user's Bertini 1.x binary on the paper's
system, in a run folder (backends.bertini_cli)."""

from __future__ import annotations

from pathlib import Path

from ..params import Params
from ..settings import Settings
from .result import Timings


def paper_command(params: Params, settings: Settings, system, folder: Path, title: str, t: Timings):
    """The paper's system by the Bertini binary in `folder`: its endpoints and what produced
    them (Bertini 1's failed paths truncated on their way to infinity not counted lost)."""
    from ..backends.bertini_cli import solve_cli

    with t.stage("solve"):
        cs = solve_cli(system, settings, folder, params.as_dict(), title)
    t.stages.update(cs.timings)
    run = cs.run
    engine = {"flavour": run.engine.flavour, "path": run.engine.path, "version": run.version}
    details = {
        "output_layout": cs.output.layout,
        "bertini_seconds": cs.run.seconds,
        "bertini1_failed_paths_file": cs.output.failed_paths,
        "crossings_unresolved": cs.run.crossings_unresolved,
    }
    if cs.attempts:
        details["attempts"] = cs.attempts
    out = cs.output
    # Bertini 1 lists failed paths; those truncated on their way to infinity are not lost.
    lost = None if out.failed_paths is None else out.failed_paths - (out.truncated_infinite or 0)
    return cs.endpoints, cs.paths_tracked, lost, engine, details, cs.input_text, None
