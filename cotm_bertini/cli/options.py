"""Options shared by the subcommands, and their translation into Params and Settings."""

from __future__ import annotations

import argparse
import difflib
import re
import sys
from pathlib import Path

from ..errors import ParameterError
from ..params import (
    CASES,
    PARAM_NAMES,
    PARAM_UNITS,
    TABLE1,
    Params,
    load_toml,
    make_params,
    parse_assignment,
)
from ..settings import Settings

# Exit codes (docs/cli.md).
EXIT_OK = 0
EXIT_DISAGREE = 1
EXIT_USAGE = 2
EXIT_SOLVER = 3
EXIT_CERTIFICATE = 4
EXIT_INCOMPLETE = 5


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit code 2; an unknown option or command is named,
    with the nearest known one."""

    def parse_known_args(self, args=None, namespace=None):
        """argparse's, after each --option of a command is checked against its known ones."""
        if args is None and self._subparsers is not None:
            args = sys.argv[1:]
        if args is not None:  # the command's own options, or those before the command
            unknown_option(self, list(args), self._subparsers is not None)
        return super().parse_known_args(args, namespace)

    def error(self, message: str) -> None:
        command = re.match(r"argument COMMAND: invalid choice: '([^']*)'", message)
        if command and self._subparsers is not None:
            known = list(self._subparsers._group_actions[0].choices)
            hint = _nearest(command[1], known) or f" (commands: {', '.join(known)})"
            message = f"unknown command {command[1]!r}{hint}"
        self.exit(EXIT_USAGE, f"cotm-bertini: error: {message}\n")


def _nearest(word: str, known: list[str]) -> str:
    """' (did you mean X?)' for the closest known word, if one is close."""
    close = difflib.get_close_matches(word, known, n=1, cutoff=0.6)
    return f" (did you mean {close[0]}?)" if close else ""


def unknown_option(parser: argparse.ArgumentParser, args: list[str], top: bool = False) -> None:
    """Refuse a --option the command does not know (argparse would take its value for the
    case, or say only "unrecognized arguments"), naming the nearest known one. An unambiguous
    prefix of a known option is argparse's to accept. `top`: the program's own options, those
    before the command."""
    known = [s for s in parser._option_string_actions if s.startswith("--")]
    for arg in args:
        if arg == "--" or (top and not arg.startswith("-")):  # the rest: values, or a command's
            return
        if not arg.startswith("--"):
            continue
        name = arg.split("=", 1)[0]
        if not any(k.startswith(name) for k in known):
            where = (" (a command's options go after it: `cotm-bertini COMMAND --help`)" if top
                     else f" (`{parser.prog} --help` lists them)")  # fmt: skip
            parser.error(f"unknown option {name}{_nearest(name, known) or where}")


# Without a case the parameters are Table 1 as printed (L01 = L02 = 0), as for cb.Params(): one
# rule for every command (docs/cli.md).
NO_CASE = "none: Table 1 as printed, L01 = L02 = 0"
NO_CASE_LABEL = "table1"


def add_case(p: argparse.ArgumentParser, default: str = NO_CASE) -> None:
    """The positional case preset."""
    p.add_argument(
        "case",
        nargs="?",
        choices=sorted(CASES),
        help="preset for L01/L02 (case1: 0, 0; case2: 11.5, 0; case3: 11.5, 11.5); "
        f"default {default}",
    )


def add_params(p: argparse.ArgumentParser) -> None:
    """--framework FILE, --params FILE and --set NAME=VALUE."""
    p.add_argument(
        "--framework",
        metavar="FILE.toml",
        help="solve your own mechanism: a framework file (docs/frameworks.md, examples/); "
        "--set then sets its [parameters]",
    )
    p.add_argument(
        "--params",
        metavar="FILE.toml",
        help=f"TOML file with any of: {' '.join(PARAM_NAMES)} (the rest: Table 1)",
    )
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="override one parameter (repeatable; applied after --params)",
    )


def add_route(p: argparse.ArgumentParser) -> None:
    """The seed and the generic-set route (also `params`: they decide a first solve's work)."""
    p.add_argument("--seed", type=int, help="random seed of the solver (default 1)")
    p.add_argument(
        "--generic",
        choices=("monodromy", "total-degree", "both"),
        help="how a generic solution set is found: monodromy, trace-tested; total-degree, "
        "a start tracked on a projective patch, two seeds agree (the route with --scheduler); "
        "or both (the monodromy set checked against the total-degree one). Default: for a "
        "framework's taut set, total-degree when its two seeds track at most 5,000 paths, "
        "else monodromy (params --framework says which and why); the paper's mechanism by "
        "monodromy; after a failed trace test the default falls back to total-degree",
    )
    p.add_argument(
        "--route",
        choices=("real", "complex"),
        help="how a framework is solved: real (branch and bound over its configuration space, "
        "real equilibria only, proved complete; circles and tori of planar bodies' angles, "
        "four-bars, products of spheres of nodes hung on bars, nodes held by springs and "
        "cables alone) or complex (every complex root of "
        "every taut set); default: real where it covers the configuration space; the paper's "
        "cases: Bertini, or the real route's search with --route real",
    )


def add_settings(p: argparse.ArgumentParser) -> None:
    """The solver settings every solving subcommand accepts (all honoured or refused)."""
    add_route(p)
    p.add_argument(
        "--engine",
        choices=("homotopy", "cli"),
        help="homotopy: parameter homotopy in-process from a cached generic solution set "
        "(default); cli: total-degree solve by the bertini2 command (or --bertini)",
    )
    p.add_argument(
        "--mptype",
        type=int,
        choices=(0, 1, 2),
        help="precision: 0 double, 1 fixed higher (cli engine only), 2 adaptive (default)",
    )
    p.add_argument(
        "--timeout",
        type=float,
        help="seconds before the solve is stopped (default: 600 for cli, none in-process)",
    )
    p.add_argument("--threads", type=int, help="solver threads (default: every core)")
    p.add_argument(
        "--bertini",
        metavar="PATH",
        help="a Bertini 1.x binary instead of bertini2 (implies --engine cli; also $COTM_BERTINI)",
    )


def overrides(args: argparse.Namespace) -> dict[str, float]:
    """--params FILE.toml, then each --set NAME=VALUE."""
    values: dict[str, float] = {}
    if args.params:
        values.update(load_toml(args.params, "--params"))
    for text in args.set:
        name, value = parse_assignment(text)
        values[name] = value
    return values


# The commands that take --framework; the others refuse it (the paper's mechanism only, so far).
FRAMEWORK_COMMANDS = ("solve", "params", "sweep", "certify", "map", "barriers", "move", "plan")


def params_from(args: argparse.Namespace):
    """The parameters a command line asks for: Table 1, the case, the file, the --set's (every
    command, `params` included, reads them here); with --framework, that framework with its
    [parameters] and the --set's."""
    if getattr(args, "framework", None):
        return framework_from(args)
    return make_params(getattr(args, "case", None), overrides(args))


def framework_from(args: argparse.Namespace):
    """The framework of --framework with each --set NAME=VALUE applied to its parameters."""
    from ..model.framework.spec import Framework

    if args.command not in FRAMEWORK_COMMANDS:
        raise ParameterError(
            f"--framework: `{args.command}` works on the paper's mechanism only so far "
            f"(frameworks: {', '.join(FRAMEWORK_COMMANDS)})"
        )
    if getattr(args, "case", None) or args.params:
        raise ParameterError("--framework: a case or --params describes the paper's mechanism")
    fw = Framework.from_toml(args.framework)
    values = {}
    for text in args.set:
        name, sep, value = text.partition("=")
        if not sep:
            raise ParameterError(f"--set {text!r}: expected NAME=VALUE")
        values[name.strip()] = value.strip()
    return fw.replace(**values)


def path_from(texts: list[str]) -> dict[str, list[float]]:
    """--path NAME=V0,V1,... (repeatable) as {name: [v0, v1, ...]}."""
    path: dict[str, list[float]] = {}
    for text in texts:
        name, sep, values = text.partition("=")
        name = name.strip()
        try:
            numbers = [float(v) for v in values.split(",")]
        except ValueError:
            numbers = []
        if not sep or not name or not numbers:
            raise ParameterError(f"--path {text!r}: expected NAME=V0,V1,... (numbers)")
        if name in path:
            raise ParameterError(f"--path {name}: given twice")
        path[name] = numbers
    return path


def describe(params) -> str:
    """The free lengths a command used, and every other value that is not Table 1's (for a
    framework: its parameter values)."""
    values = params.as_dict()
    if not isinstance(params, Params):
        return ", ".join(f"{n} = {v:.12g}" for n, v in values.items()) or "no parameters"
    free = [f"{n} = {values[n]:.12g} {PARAM_UNITS[n]}" for n in ("L01", "L02")]
    changed = [
        f"{n} = {v:.12g} {PARAM_UNITS[n]}"
        for n, v in values.items()
        if n not in ("L01", "L02") and v != TABLE1[n]
    ]
    return ", ".join(free) + (f"; {', '.join(changed)}" if changed else "")


def label_of(args: argparse.Namespace) -> str:
    """A run's label: the case named, else the parameter file's name, else `custom` for --set."""
    if getattr(args, "framework", None):
        return Path(args.framework).stem
    if args.case:
        return args.case
    if args.params:
        return Path(args.params).stem
    return "custom" if args.set else NO_CASE_LABEL


def settings_from(args: argparse.Namespace) -> Settings:
    """Settings from the options the user gave (the others stay at their defaults)."""
    given = {
        name: getattr(args, name)
        for name in (
            "seed",
            "engine",
            "mptype",
            "timeout",
            "threads",
            "bertini",
            "generic",
            "route",
        )
        if getattr(args, name, None) is not None
    }
    if getattr(args, "only", None) is not None:
        given["only"] = args.only
    return Settings(**given)


def add_only(p: argparse.ArgumentParser) -> None:
    """--only: every equilibrium, or the stable ones alone (a solve, a sweep or a map)."""
    p.add_argument(
        "--only",
        choices=("all", "stable"),
        help="what is looked for: all equilibria (default), or the stable ones alone, each "
        "proved a strict local minimum and none missing (the real route: boxes where V can "
        "have no local minimum are dropped; no saddle, maximum or Morse count)",
    )
