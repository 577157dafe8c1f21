"""Scene presets: the TOML scenes of the repository's ``inputs/`` folder, shipped with the
package as ``demstudy/presets/<group>/<name>.toml`` (CMake ``install(DIRECTORY inputs/ …)``).

A preset is named by its path below ``inputs/`` without the suffix, e.g.
``"campbell1982/chute-30"`` (``"campbell1982/chute-30.toml"`` is accepted too).

Where presets are looked for, first match wins:

1. a source checkout's ``inputs/`` (the folder next to the ``demstudy`` package, when a
   ``pyproject.toml`` sits beside it): edits there count at once, also in an editable install;
2. ``demstudy/presets`` in the installed package (a wheel; an editable install, whose CMake
   install tree holds a copy made at install time), through ``importlib.resources`` and each
   entry of ``demstudy.__path__``.

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (each scene file's header
comment says what sets its time unit).
"""

from __future__ import annotations

import difflib
import importlib.resources
from pathlib import Path

from .base import SceneError

__all__ = ["find_preset", "list_presets", "preset_path", "preset_roots"]

SUFFIX = ".toml"
PACKAGE_FOLDER = "presets"


def _checkout_inputs() -> Path | None:
    """``inputs/`` of the source tree this module was imported from, if it is a checkout."""
    root = Path(__file__).resolve().parents[2]  # demstudy/scene/presets.py -> the tree
    inputs = root / "inputs"
    if inputs.is_dir() and (root / "pyproject.toml").is_file():
        return inputs
    return None


def preset_roots() -> list[Path]:
    """The folders searched for presets, in order (existing ones only, no duplicates)."""
    candidates: list[Path] = []
    checkout = _checkout_inputs()
    if checkout is not None:
        candidates.append(checkout)
    try:
        packaged = importlib.resources.files("demstudy") / PACKAGE_FOLDER
        if isinstance(packaged, Path):  # a folder on disk (wheels and editable installs)
            candidates.append(packaged)
    except (ModuleNotFoundError, TypeError, ValueError, OSError):
        pass
    import demstudy  # noqa: PLC0415 (the package's search path, after any import hooks ran)

    candidates += [Path(entry) / PACKAGE_FOLDER for entry in getattr(demstudy, "__path__", [])]
    roots: list[Path] = []
    for path in candidates:
        try:
            resolved = path.resolve()
        except OSError:
            continue
        if resolved.is_dir() and resolved not in roots:
            roots.append(resolved)
    return roots


def _index() -> dict[str, Path]:
    """Preset name -> file, the first root holding a name winning."""
    found: dict[str, Path] = {}
    for root in preset_roots():
        for path in sorted(root.rglob(f"*{SUFFIX}")):
            if path.is_file():
                name = path.relative_to(root).with_suffix("").as_posix()
                found.setdefault(name, path)
    return found


def list_presets() -> list[str]:
    """Every preset name, sorted: ``["campbell1982/chute-20", …, "shear/lees-edwards-3d"]``."""
    return sorted(_index())


def normalise(name: str) -> str:
    """A preset name as listed: slashes, no leading ``./`` or trailing ``.toml``."""
    text = str(name).strip().replace("\\", "/")
    while text.startswith("./"):
        text = text[2:]
    return text.removesuffix(SUFFIX).rstrip("/")


def close_presets(name: str, names: list[str] | None = None, n: int = 3) -> list[str]:
    """Presets resembling ``name``: same file name in another group first, then the closest
    spellings of the whole name and of the file name."""
    names = list_presets() if names is None else names
    key = normalise(name)
    stem = key.rsplit("/", 1)[-1]
    same = [p for p in names if p.rsplit("/", 1)[-1] == stem]
    spelled = difflib.get_close_matches(key, names, n=n, cutoff=0.6)
    by_stem = {p.rsplit("/", 1)[-1]: p for p in names}
    spelled += [by_stem[s] for s in difflib.get_close_matches(stem, list(by_stem), n=n,
                                                               cutoff=0.6)]
    return list(dict.fromkeys(same + spelled))[:n]


def unknown_preset_problem(name: str) -> str:
    """The message for a name that is neither a file nor a preset."""
    names = list_presets()
    close = close_presets(name, names)
    text = f"{normalise(name)!r} is not a preset"
    if close:
        text += "; did you mean " + " or ".join(repr(c) for c in close) + "?"
    if names:
        text += f" (presets: {', '.join(names)})"
    else:
        text += " (no presets found: neither a checkout's inputs/ nor demstudy/presets)"
    return text


def find_preset(name: str) -> Path | None:
    """The file of preset ``name``, or None."""
    return _index().get(normalise(name))


def preset_path(name: str) -> Path:
    """The file of preset ``name`` (``"campbell1982/chute-30"``, with or without ``.toml``);
    ``SceneError`` naming it, with the close matches and every preset, when unknown."""
    found = find_preset(name)
    if found is None:
        raise SceneError(str(name), [unknown_preset_problem(name)])
    return found
