"""The bifurcation diagram of a framework's one-parameter sweep: each pose coordinate of the
physical equilibria against the parameter, stable ones solid, unstable ones faint, events
marked."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure

from ..model.framework.spec import Framework
from .common import flag, save, set_title, values_line


def _quantities(fw: Framework, table: pd.DataFrame) -> list[str]:
    """What to draw: planar angles, quaternions, node coordinates, else the energy."""
    names = [f"{b}.angle_deg" for b, _ in fw.bodies] if fw.dim == 2 else []
    names += [f"{b}.q{c}" for b, _ in fw.bodies for c in "wxyz"] if fw.dim == 3 else []
    names += [f"{n}.{a}" for n in fw.nodes for a in "xyz"[: fw.dim]]
    return [n for n in names if n in table][:6] or ["energy"]


# Where equilibria are born or end: marker, face colour, label (the events.csv kinds).
EVENT_MARKERS = {
    "fold": ("x", "black", "fold"),
    "pitchfork": ("P", "white", "pitchfork (three branches meet)"),
    "cable_switch": ("s", "white", "cable switch (a cable at its free length)"),
}


def _mark_events(ax, events: pd.DataFrame, param: str, name: str) -> None:
    """Each fold, pitchfork and cable switch at its pose, one legend entry a kind present."""
    if name not in events:
        return
    for kind, (marker, face, label) in EVENT_MARKERS.items():
        rows = events[events["kind"] == kind]
        if len(rows):
            ax.plot(rows[param], rows[name], marker, ls="", color="black", mfc=face, ms=7,
                    mew=1.6, label=label)  # fmt: skip


def plot_framework_sweep(
    fw: Framework, table: pd.DataFrame, param: str, path: str | Path, events=None
) -> list[Path]:
    """Write the diagram to `path` (see plot.common.save); returns the files written."""
    names = _quantities(fw, table)
    fig = Figure(figsize=(7.5, 2.6 * len(names) + 0.6))
    axes = fig.subplots(len(names), 1, sharex=True, squeeze=False)[:, 0]
    physical = flag(table, "physical")
    stable = physical & flag(table, "stable")
    for ax, name in zip(axes, names, strict=True):
        x, y = table[param].to_numpy(float), table[name].to_numpy(float)
        ax.plot(x[physical & ~stable], y[physical & ~stable], ".", ms=2.5, color="tab:red",
                alpha=0.55, label="unstable")  # fmt: skip
        ax.plot(x[stable], y[stable], ".", ms=4, color="tab:blue", label="stable")
        if events is not None and len(events):
            for _, e in events.iterrows():
                ax.axvline(e[param], color="0.5", lw=0.6, ls=":")
            _mark_events(ax, events, param, name)
        ax.set_ylabel(name)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel(param)
    axes[0].legend(loc="best", fontsize=8)
    fixed = values_line(fw.values, leave_out=[param])
    set_title(fig, f"{fw.name}: physical equilibria against {param}" + (f"\n{fixed}" if fixed
                                                                        else ""))  # fmt: skip
    fig.tight_layout()
    return save(fig, path)
