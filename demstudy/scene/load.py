"""Read, override and validate scene files; every problem becomes one ``SceneError``."""

from __future__ import annotations

import copy
import os
import re
import tomllib
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import ValidationError

from . import presets
from .base import SceneError, nearest
from .scene import Scene

_TANGENTIAL_TAGS = ("smooth", "beta", "rough", "coulomb", "campbell-noslip")


#: What a strict scalar field takes (the scene's numbers and switches are never coerced).
_STRICT_TYPES = {"float_type": "a number (integer or decimal, e.g. 1 or 0.5)",
                 "int_type": "an integer (e.g. 3)", "bool_type": "true or false"}
_TOML_TYPE = {"bool": "boolean", "str": "string", "float": "decimal number", "list": "array",
              "int": "integer"}


def _location(loc: tuple) -> str:
    parts: list[str] = []
    previous = None
    for item in loc:
        after, previous = previous, item
        if isinstance(item, int):
            parts[-1:] = [f"{parts[-1]}[{item}]"] if parts else [f"[{item}]"]
        elif after == "tangential" and item in _TANGENTIAL_TAGS:
            continue  # discriminated-union tag (not the field `beta` inside model = 'beta')
        elif isinstance(item, str) and (
            "[" in item or "|" in item or item.startswith(("function", "constrained-"))
            or item in ("float", "int", "str", "bool")
        ):
            continue  # pydantic's internal union-member labels
        else:
            parts.append(str(item))
    return ".".join(parts) or "(top level)"


def _describe(error: dict) -> str:
    where = _location(error.get("loc", ()))
    message = error.get("msg", "invalid").removeprefix("Value error, ")
    value = error.get("input")
    kind = error.get("type", "")
    if kind == "missing":
        return f"{where}: required field is missing"
    if kind == "union_tag_invalid":
        tag = error.get("ctx", {}).get("tag")
        return f"{where}.model = {tag!r}: {message}"
    if kind in ("model_type",) or isinstance(value, dict):
        return f"{where}: {message}"
    shown = repr(value)
    if len(shown) > 60:
        shown = shown[:57] + "..."
    if kind in _STRICT_TYPES:  # a boolean or a string where a number (or boolean) belongs
        return (f"{where} = {shown}: {_STRICT_TYPES[kind]} is allowed, not a "
                f"{_TOML_TYPE.get(type(value).__name__, type(value).__name__)}")
    return f"{where} = {shown}: {message}"


def validate_scene(data: Mapping[str, Any], source: str = "<scene>") -> Scene:
    """Validate a scene mapping (as read from TOML); raise ``SceneError`` on any problem."""
    if not isinstance(data, Mapping):
        raise SceneError(source, [f"(top level): expected a table, got {type(data).__name__}"])
    check_depth(data, source)
    try:
        scene = Scene.model_validate(dict(data))
    except ValidationError as exc:
        problems = list(dict.fromkeys(_describe(e) for e in exc.errors(include_url=False)))
        raise SceneError(source, problems) from None
    except (ValueError, TypeError, ArithmeticError) as exc:  # a rule that tripped on bad input
        raise SceneError(source, [f"(top level): {exc}"]) from None
    from ..contact.stiffness import stiffness_problem  # numpy: the contact mapping

    problem = stiffness_problem(scene)
    if problem:  # every soft engine would fail on it, so the scene is refused for all
        raise SceneError(source, [problem])
    return scene


def parse_value(text: str) -> Any:
    """A ``--set`` value: a TOML literal (number, bool, string, array, inline table) or a bare
    string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except (tomllib.TOMLDecodeError, RecursionError):  # the depth check refuses the string
        return text


def apply_overrides(data: dict, overrides: Iterable[str], source: str = "--set") -> dict:
    """Return a copy of ``data`` with ``key.path=value`` overrides applied (list items by
    index: ``walls.0.restitution`` or ``walls[0].restitution``).

    Unknown top-level sections are reported with the nearest valid name; the full
    validation then checks the keys inside.
    """
    data = copy.deepcopy(data)
    problems = []
    for item in overrides:
        key, sep, text = item.partition("=")
        key = re.sub(r"\[(\d+)\]", r".\1", key.strip())  # walls[0].x is walls.0.x
        if not sep or not key:
            problems.append(f"{item!r}: expected key.path=value, e.g. run.production=20")
            continue
        path = key.split(".")
        if path[0] not in Scene.model_fields:
            hint = nearest(path[0], sorted(Scene.model_fields))
            problems.append(
                f"{key}: unknown section {path[0]!r}"
                + (f"; did you mean {hint!r}?" if hint else "")
            )
            continue
        node: Any = data
        for part in path[:-1]:
            if isinstance(node, list):
                if not part.isdigit() or int(part) >= len(node):
                    problems.append(f"{key}: {part!r} is not an index of a list of {len(node)}")
                    break
                node = node[int(part)]
            else:
                node = node.setdefault(part, {})
                if not isinstance(node, dict | list):
                    problems.append(f"{key}: {part!r} is a value, not a table")
                    break
        else:
            last = path[-1]
            if isinstance(node, list):
                if last.isdigit() and int(last) < len(node):
                    node[int(last)] = parse_value(text)
                else:
                    problems.append(f"{key}: {last!r} is not an index of a list of {len(node)}")
            else:
                node[last] = parse_value(text)
    if problems:
        raise SceneError(source, problems)
    return data


#: Deepest nesting of tables and arrays a scene may have (a real scene nests ~4 deep); deeper
#: data is refused before copying or validating it, which would exhaust Python's stack.
MAX_DEPTH = 32


def read_scene_data(path: str | Path, source: str | None = None) -> dict:
    """The TOML data of a scene file; ``SceneError`` (naming ``source``, default the path)
    if it cannot be read, is not UTF-8, is not TOML or nests deeper than ``MAX_DEPTH``."""
    path = Path(path)
    source = str(path) if source is None else source
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise SceneError(source, [f"cannot read the file: {exc.strerror or exc}"]) from None
    try:
        text = raw.decode("utf-8")  # TOML is UTF-8 (read_text would use the locale's)
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise SceneError(source, [
            f"not UTF-8 text: byte 0x{raw[exc.start]:02x} at line {line} (byte offset "
            f"{exc.start}); TOML files must be UTF-8"]) from None
    return parse_scene_text(text, source)


def parse_scene_text(text: str, source: str = "<scene>") -> dict:
    """Parse TOML text; ``SceneError`` if it is not TOML or nests deeper than ``MAX_DEPTH``."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(source, [f"not valid TOML: {exc}"]) from None
    except RecursionError:  # tomllib parses nested arrays and inline tables recursively
        raise SceneError(source, [_too_deep("(top level)")]) from None
    check_depth(data, source)
    return data


def _too_deep(where: str) -> str:
    return (f"{where}: values nested more than {MAX_DEPTH} deep (arrays or tables inside "
            f"each other); a scene nests at most {MAX_DEPTH}")


def check_depth(data: Any, source: str = "<scene>") -> None:
    """``SceneError`` naming the first field nested deeper than ``MAX_DEPTH`` (iterative, so
    any depth is measured without recursion)."""
    stack: list[tuple[Any, str, int]] = [(data, "", 0)]
    while stack:
        node, where, depth = stack.pop()
        if not isinstance(node, Mapping | list | tuple):
            continue
        if depth > MAX_DEPTH:
            raise SceneError(source, [_too_deep(where or "(top level)")])
        items = node.items() if isinstance(node, Mapping) else enumerate(node)
        for key, value in items:
            label = f"{where}[{key}]" if not isinstance(node, Mapping) else (
                f"{where}.{key}" if where else str(key))
            stack.append((value, label, depth + 1))


def resolve_scene(source: str | os.PathLike) -> tuple[Path, str]:
    """The file of ``source`` and the name errors give it: an existing file (it wins), else
    the preset of that name (:mod:`demstudy.scene.presets`). Neither: ``SceneError`` saying
    why the file cannot be read and which presets are close."""
    path = Path(source)
    if path.is_file():
        return path, str(path)
    found = presets.find_preset(str(source))
    if found is not None:
        return found, f"{presets.normalise(str(source))} (preset {found})"
    try:
        path.read_bytes()
        reason = "not a file"
    except OSError as exc:
        reason = exc.strerror or str(exc)
    problem = f"cannot read the file: {reason}"
    if not path.is_absolute():  # a relative name may have meant a preset
        problem += "; " + presets.unknown_preset_problem(str(source))
    raise SceneError(str(source), [problem])


def _plain(value: Any) -> Any:
    """numpy scalars and arrays as Python numbers and lists; tuples as lists (TOML types)."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value


def apply_sections(data: dict, sections: Mapping[str, Any], source: str = "keywords") -> dict:
    """Return a copy of ``data`` with keyword sections merged in (``load_scene(…, run={…})``).

    Each key is a top-level section (``run``, ``walls``, ``dimension``, …); its value is
    merged into the scene data before validation:

    * a dict merges into a table key by key, recursively (like one ``--set`` per leaf),
      except that a dict naming another ``model`` than the table's replaces the table (a
      tangential rule or restitution law of another model keeps none of the old one's
      parameters);
    * a dict with integer keys merges into a list item by index
      (``walls={0: {"restitution": 0.9}}``); a list replaces the whole list;
    * any other value replaces the key; ``None`` removes it (the schema default applies).

    Unknown sections and bad indices raise ``SceneError`` naming the field; keys inside a
    section are checked by the validation (``run: unknown key 'prodution'; did you mean
    'production'?``).
    """
    data = copy.deepcopy(data)
    problems: list[str] = []

    def merge(node: dict | list, key: Any, value: Any, where: str) -> None:
        value = _plain(value)
        if isinstance(node, list):
            if isinstance(key, str) and key.isdigit():
                key = int(key)
            if isinstance(key, bool) or not isinstance(key, int) or not 0 <= key < len(node):
                problems.append(f"{where}: {key!r} is not an index of a list of {len(node)} "
                                "(give a whole list to replace it)")
                return
        elif not isinstance(key, str):
            problems.append(f"{where}: a table's keys are strings, got {key!r}")
            return
        if value is None:
            if isinstance(node, list):
                problems.append(f"{where}: None cannot remove a list item (give the whole list)")
            else:
                node.pop(key, None)
            return
        current = node[key] if isinstance(node, list) else node.get(key)
        if (isinstance(value, Mapping) and isinstance(current, dict)
                and "model" in value and value["model"] != current.get("model")):
            current = None  # another model: a fresh table
        if isinstance(value, Mapping) and isinstance(current, dict | list):
            for sub, item in value.items():
                label = f"{where}[{sub}]" if isinstance(current, list) else f"{where}.{sub}"
                merge(current, sub, item, label)
        elif isinstance(value, Mapping):
            fresh: dict = {}
            for sub, item in value.items():
                merge(fresh, sub, item, f"{where}.{sub}")
            node[key] = fresh
        else:
            node[key] = copy.deepcopy(value)

    for name, value in sections.items():
        if name not in Scene.model_fields:
            hint = nearest(name, sorted(Scene.model_fields))
            problems.append(f"{name}: unknown section {name!r}"
                            + (f"; did you mean {hint!r}?" if hint else "")
                            + f" (sections: {', '.join(sorted(Scene.model_fields))})")
            continue
        merge(data, name, value, name)
    if problems:
        raise SceneError(source, problems)
    return data


def load_scene(source: str | os.PathLike, overrides: Iterable[str] = (),
               **sections: Any) -> Scene:
    """Read a scene, apply overrides, validate; raise ``SceneError`` if anything is invalid.

    ``source``: a TOML file, or a preset name such as ``"campbell1982/chute-30"`` (see
    :func:`demstudy.scene.presets.list_presets`; an existing file of that name wins).
    ``sections``: typed values merged in first (:func:`apply_sections`), e.g.
    ``load_scene("campbell1982/couette-noslip", run={"production": 50})``;
    ``overrides``: ``--set`` strings ``key.path=value`` applied after them.
    """
    if isinstance(overrides, str):  # one override given as a string, not a list of them
        overrides = [overrides]
    path, name = resolve_scene(source)
    data = read_scene_data(path, name)
    if sections:
        check_depth(sections, f"{name} (keyword overrides)")
        data = apply_sections(data, sections, source=f"{name} (keyword overrides)")
    data = apply_overrides(data, overrides, source=name)
    _anchor_files(data, path.parent)
    return validate_scene(data, name)


def _anchor_files(data: dict, folder: Path) -> None:
    """Files a scene names (a lattice's Gutt initial-data file) are relative to the scene
    file's folder, not to where demstudy runs; made absolute here so that the scene, stored
    in a results file or a checkpoint, validates from anywhere."""
    lattice = data.get("lattice")
    if isinstance(lattice, dict) and isinstance(lattice.get("initial_file"), str):
        given = Path(lattice["initial_file"]).expanduser()
        if not given.is_absolute():
            lattice["initial_file"] = str((folder / given).resolve())


def flat_fields(table: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Scene data by dotted field names: {"run.production": 2.0, "walls": [...], ...} (arrays
    of tables stay whole). Used to say which fields two scenes differ in."""
    out: dict[str, Any] = {}
    for key, value in table.items():
        if isinstance(value, Mapping):
            out.update(flat_fields(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


def scene_to_toml(scene: Scene) -> str:
    """A canonical TOML rendering of a validated scene (stored in every results file)."""
    return dump_toml(scene.model_dump(mode="json", exclude_none=True))


def dump_toml(data: Mapping[str, Any]) -> str:
    """Minimal TOML writer for scene data (tables, arrays of tables, scalars, arrays)."""
    lines: list[str] = []

    def scalar(value: Any) -> str:
        if isinstance(value, bool):
            return "true" if value else "false"
        if isinstance(value, int | float):
            return repr(value)
        if isinstance(value, str):
            return _toml_string(value)
        if isinstance(value, list):
            return "[" + ", ".join(scalar(v) for v in value) + "]"
        if isinstance(value, dict):
            return "{ " + ", ".join(f"{k} = {scalar(v)}" for k, v in value.items()) + " }"
        raise TypeError(f"cannot write {type(value).__name__} to TOML")

    def table(prefix: str, mapping: Mapping[str, Any], header: str | None) -> None:
        plain = {k: v for k, v in mapping.items() if not _is_table(v) and not _is_table_array(v)}
        if header is not None:
            lines.append("")
            lines.append(header)
        for k, v in plain.items():
            lines.append(f"{k} = {scalar(v)}")
        for k, v in mapping.items():
            name = f"{prefix}{k}"
            if _is_table(v):
                table(name + ".", v, f"[{name}]")
            elif _is_table_array(v):
                for item in v:
                    table(name + ".", item, f"[[{name}]]")

    table("", data, None)
    return "\n".join(lines).lstrip("\n") + "\n"


def _toml_string(text: str) -> str:
    """A TOML basic string: quote, backslash and control characters escaped (newlines too)."""
    out = []
    for ch in text:
        if ch in '"\\':
            out.append("\\" + ch)
        elif ch == "\n":
            out.append("\\n")
        elif ch == "\t":
            out.append("\\t")
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _is_table(value: Any) -> bool:
    return isinstance(value, dict)


def _is_table_array(value: Any) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)
