"""Files shipped inside the package: the Jinja2 templates of the Bertini input files."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

TEMPLATE_NAMES = ("zero_dim.input.j2", "system.input.j2", "parameter_homotopy.input.j2")


def template_texts() -> dict[str, str]:
    """Every template's text, by file name (from the installed package, or a checkout).

    In a wheel the templates are the package data `cotm_bertini/templates/`; pyproject.toml maps
    that package onto the top-level `templates/` folder of the repository.
    """
    try:
        folder = resources.files("cotm_bertini.templates")
        return {name: folder.joinpath(name).read_text() for name in TEMPLATE_NAMES}
    except (ModuleNotFoundError, FileNotFoundError, NotADirectoryError):
        folder = Path(__file__).resolve().parent.parent / "templates"
        return {name: (folder / name).read_text() for name in TEMPLATE_NAMES}


PAGE_NAMES = ("explore.html.j2",)  # page templates: not part of any solve's cache key


def page_template(name: str) -> str:
    """A page template's text (the explorer's), from the installed package or a checkout."""
    if name not in PAGE_NAMES:
        raise KeyError(name)
    try:
        return resources.files("cotm_bertini.templates").joinpath(name).read_text()
    except (ModuleNotFoundError, FileNotFoundError, NotADirectoryError):
        return (Path(__file__).resolve().parent.parent / "templates" / name).read_text()
