"""The results file: one HDF5 layout for every engine (see docs/results-format.md).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
or the shear rate sets the time scale); the root attribute ``units`` says so in every file and
``time_unit`` says what the time unit τ of this scene is. Every dataset carries the attributes
``units`` and ``description`` (:mod:`demstudy.io.fields`).
Writes are atomic: the file is built in memory, written under a temporary name, flushed
and renamed into place.

Attributes keep their Python types: int, float, bool and str are stored as HDF5 scalars and
read back as int, float, bool and str (numpy scalars come back as the Python type); numpy
arrays as arrays (read back as arrays). ``None``, dicts, lists and tuples are stored as JSON
text and their names listed in the attribute ``json_attributes`` (a JSON list) of the same
object; they read back as None, dict (string keys) and list (a tuple becomes a list).
Anything else is stored as its ``str()``.
"""

from __future__ import annotations

import datetime as _dt
import io
import json
import os
import platform
import shlex
import sys
import tomllib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from .. import UNITS_NOTE, __version__
from .fields import field_info, time_unit
from .frames import WALLS, Frame

FORMAT_VERSION = 1


JSON_ATTRIBUTES = "json_attributes"
"""Attribute listing (as a JSON list) the attributes of the same object stored as JSON."""

COMMAND_LINE_ENV = "DEMSTUDY_COMMAND_LINE"
"""Environment variable carrying the user's command line into engine child processes
(:func:`set_command_line`)."""


@dataclass
class Results:
    """The content of a results file, and what a researcher does with it.

    ``attrs`` (root attributes: ``units``, ``engine``, ``scene_toml``, …), ``timeseries``,
    ``profiles`` (with ``*_err``) and ``profile_attrs``, ``frames`` (when kept), ``groups``
    (``"stress"``, ``"statistics/<name>"``, ``"collisions"``) with ``group_attrs``;
    ``dataset_attrs``: extra attributes of single datasets, keyed by their path without the
    leading slash (``"timeseries/time"``), over the ``units`` and ``description`` the writer
    takes from :mod:`demstudy.io.fields`; :func:`read_results` fills it with every dataset's
    attributes. ``path``: the file it was read from or last written to.

    :meth:`analyze` adds statistics (and saves them in the file), :meth:`plot` draws a
    figure, :attr:`scene` is the run's scene, :meth:`frames` its stored frames. Dimensionless
    particle units: d = 1, m = 1, g = 1 when gravity acts."""

    attrs: dict[str, Any]
    timeseries: dict[str, np.ndarray] = field(default_factory=dict)
    profiles: dict[str, np.ndarray] = field(default_factory=dict)
    profile_attrs: dict[str, Any] = field(default_factory=dict)
    frames: dict[str, np.ndarray] | None = None
    groups: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    group_attrs: dict[str, dict[str, Any]] = field(default_factory=dict)
    dataset_attrs: dict[str, dict[str, Any]] = field(default_factory=dict)
    path: Path | None = field(default=None, compare=False)
    skipped: tuple[str, ...] = field(default=(), compare=False)  # groups not read (``skip``)

    @property
    def scene(self) -> Any:
        """The scene the run was made with (the analysis scene when ``analyze`` was given
        another one)."""
        from ..scene import parse_scene_text, validate_scene

        text = self.attrs.get("analysis_scene_toml") or self.attrs.get("scene_toml")
        if not text:
            raise ValueError(f"{self.path or 'these results'}: no scene_toml attribute")
        source = str(self.path or "results")
        return validate_scene(parse_scene_text(text, source), source)

    def iter_frames(self, start: float = 0.0) -> Iterator[Frame]:
        """The stored frames (``keep_frames``) from time ``start`` on, as ``Frame`` objects."""
        return (f for f in frames_of(self, self.scene.dimension) if f.time >= start)

    def statistic(self, name: str) -> dict[str, np.ndarray]:
        """The datasets of a statistic (``"vdf"``, ``"stress"``, ``"derived"``, …)."""
        for key in (f"statistics/{name}", name):
            if key in self.groups:
                return self.groups[key]
        if name == "profiles" and self.profiles:
            return self.profiles
        raise KeyError(f"{self.path or 'these results'} hold no {name!r} (have: "
                       f"{', '.join(sorted(self.groups)) or 'none'}); add it with "
                       f".analyze({name!r})")

    def analyze(self, *what: Any, z_cells: int = 1, start: float = 0.0,
                save: bool = True, wall_relative: bool | None = None) -> Results:
        """Compute statistics from this run's frames, collision log or results: registered
        names (``"vdf"``, ``"gr"``, …; :data:`demstudy.analysis.registry.STATISTICS`) or
        analysis objects (an ``AnalysisBase`` run over the frames, stored under its
        ``name`` attribute or its class name). The results go into ``groups`` (profiles into
        ``profiles``) and, with ``save`` and a ``path``, into the file. ``wall_relative``:
        walls that move (servo): y bins that follow the walls (None: yes, Campbell's
        ST = HGT/FND; False: fixed strips). Returns ``self``."""
        from ..analysis.registry import Context, compute_statistics

        scene = self.scene
        names = [w for w in what if isinstance(w, str)]
        from ..analysis.walls import first_walls, strips_for

        frames = (lambda: self.iter_frames(start)) if self.frames else None
        wall_relative = strips_for(scene, frames, wall_relative, str(self.path or "these results"))
        ctx = Context(scene, frames=frames, results=self, z_cells=z_cells,
                      wall_relative=wall_relative,
                      walls=first_walls(frames) if wall_relative is False else None)
        computed = compute_statistics(names, ctx)
        for analysis in (w for w in what if not isinstance(w, str)):
            analysis.run(self.iter_frames(start))
            name = getattr(analysis, "name", type(analysis).__name__.lower())
            computed[name] = (analysis.results, analysis.attrs)
        for name, (data, attrs) in computed.items():
            if name == "profiles":
                self.profiles, self.profile_attrs = data, attrs
            else:
                self.groups[f"statistics/{name}"] = data
                self.group_attrs[f"statistics/{name}"] = attrs
        if save and self.path is not None:
            whole = self
            if self.skipped:  # read without some groups: write them back as they are
                whole = read_results(self.path)
                whole.profiles, whole.profile_attrs = self.profiles, self.profile_attrs
                whole.groups.update(self.groups)
                whole.group_attrs.update(self.group_attrs)
            write_results(self.path, whole)
        return self

    def plot(self, kind: str = "profiles", out: str | os.PathLike | None = None, *,
             others: Sequence[Results | str | os.PathLike] = (), scaled: bool = False,
             bins: Sequence[int] | None = None) -> Any:
        """The figure of ``kind`` (:data:`demstudy.plots.KINDS`) for this run, overlaid with
        ``others`` (results or files); saved to ``out`` when given. Returns the matplotlib
        Figure."""
        from ..plots import KINDS, draw
        from ..plots.common import Run, missing_notice
        from ..plots.common import save as save_figure

        if kind not in KINDS:
            raise ValueError(f"unknown plot kind {kind!r} (allowed: {', '.join(KINDS)})")
        runs = [Run.of(self)] + [Run.of(o) if isinstance(o, Results) else Run.load(o)
                                 for o in others]
        lacking = [run for run in runs if run.group(kind) is None]
        if lacking:
            raise ValueError(missing_notice(lacking[0], kind).removeprefix("notice: "))
        fig = draw(kind, runs, scaled=scaled, bins=bins)
        if out is not None:
            save_figure(fig, out)
        return fig

    def __repr__(self) -> str:
        what = ["profiles"] if self.profiles else []
        what += sorted(self.groups)
        frames = len(self.frames["time"]) if self.frames and "time" in self.frames else 0
        return (f"<Results {self.path or '(not written)'}: {self.attrs.get('scene_name', '?')} "
                f"({self.attrs.get('engine', '?')}), {', '.join(what) or 'nothing'}"
                f"{f', {frames} frames' if frames else ''}>")


# -- attributes ------------------------------------------------------------------------
def _json_default(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


def encode_attr(value: Any) -> tuple[Any, bool]:
    """(value to store, stored as JSON?) for one attribute (conventions: module doc)."""
    if value is None or isinstance(value, dict | list | tuple):
        return json.dumps(value, default=_json_default), True
    if isinstance(value, np.ndarray) and value.dtype.kind in "UO":
        return json.dumps(value.tolist(), default=_json_default), True
    if isinstance(value, str | bytes | bool | int | float | np.generic | np.ndarray):
        return value, False
    return str(value), False


def decode_attr(value: Any, is_json: bool = False) -> Any:
    """The Python value of a stored attribute (inverse of :func:`encode_attr`)."""
    if isinstance(value, bytes):
        value = value.decode()
    if isinstance(value, h5py.Empty):
        return None
    if is_json and isinstance(value, str):
        return json.loads(value)
    if isinstance(value, np.generic):
        return value.item()
    return value


def write_attrs(obj: h5py.HLObject, attrs: Mapping[str, Any]) -> None:
    """Store ``attrs`` on an HDF5 group, dataset or file keeping their types (module doc)."""
    as_json = []
    for key, value in attrs.items():
        if key == JSON_ATTRIBUTES:
            continue
        stored, is_json = encode_attr(value)
        obj.attrs[key] = stored
        if is_json:
            as_json.append(key)
    if as_json:
        obj.attrs[JSON_ATTRIBUTES] = json.dumps(as_json)


def read_attrs(obj: h5py.HLObject) -> dict[str, Any]:
    """The attributes of an HDF5 object as written by :func:`write_attrs`."""
    listed = obj.attrs.get(JSON_ATTRIBUTES)
    as_json = set(json.loads(decode_attr(listed))) if listed is not None else set()
    return {k: decode_attr(v, k in as_json) for k, v in obj.attrs.items()
            if k != JSON_ATTRIBUTES}


# -- provenance ------------------------------------------------------------------------
def set_command_line(argv: Sequence[str]) -> None:
    """Record the user's command line (e.g. ``["demstudy", *sys.argv[1:]]``) for every
    results file written by this process and its children (engine child processes and MPI
    ranks inherit the environment)."""
    os.environ[COMMAND_LINE_ENV] = shlex.join(str(a) for a in argv)


def current_command_line() -> str:
    """The command line a results file records: :func:`set_command_line`'s, else this
    process's ``sys.argv``."""
    return os.environ.get(COMMAND_LINE_ENV) or shlex.join(sys.argv)


def software_versions() -> dict[str, str]:
    return {"demstudy_version": __version__, "python_version": platform.python_version(),
            "numpy_version": np.__version__, "h5py_version": h5py.__version__,
            "hdf5_version": h5py.version.hdf5_version}


def _scene_data(attrs: Mapping[str, Any]) -> dict | None:
    text = attrs.get("scene_toml")
    if not isinstance(text, str):
        return None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        return None


def root_attrs(results: Results, command_line: str | None = None) -> dict[str, Any]:
    """The root attributes written: the defaults below, then ``results.attrs`` (a file read
    back and written again keeps its run's ``created``, ``command_line`` and versions, and
    records the latest writer in ``last_written_by``)."""
    now = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
    command = command_line or current_command_line()
    scene = _scene_data(results.attrs)
    attrs: dict[str, Any] = {
        "format_version": FORMAT_VERSION,
        **software_versions(),
        "units": UNITS_NOTE,
        "created": now,
        "command_line": command,
    }
    if scene is not None:
        try:
            attrs["time_unit"] = time_unit(scene)
        except (TypeError, ValueError, AttributeError):
            pass
    attrs.setdefault("time_unit", "not recorded: the file holds no readable scene_toml "
                                  "(see docs/scenes.md, 'Units and axes')")
    rewrite = "created" in results.attrs
    attrs.update(results.attrs)
    if command_line is not None:
        attrs["command_line"] = command_line
    if rewrite:
        versions = ", ".join(f"{k.removesuffix('_version')} {v}"
                             for k, v in software_versions().items())
        attrs["last_written_by"] = f"{command} ({versions}; {now})"
    return attrs


def _dim(attrs: Mapping[str, Any]) -> int | None:
    scene = _scene_data(attrs)
    dim = scene.get("dimension") if scene else None
    return dim if dim in (2, 3) else None


# -- writing and reading ---------------------------------------------------------------
def _write_group(group: h5py.Group, data: Mapping[str, Any], attrs: Mapping[str, Any] = {},
                 dataset_attrs: Mapping[str, Mapping[str, Any]] = {},
                 dim: int | None = None) -> None:
    key = group.name.lstrip("/")
    for name, value in data.items():
        arr = np.asarray(value)
        kwargs = {"compression": "gzip", "compression_opts": 4} if arr.size > 4096 else {}
        dataset = group.create_dataset(name, data=arr, **kwargs)
        write_attrs(dataset, {**field_info(key, name, dim),
                              **dataset_attrs.get(f"{key}/{name}", {})})
    write_attrs(group, attrs)


def write_results(path: str | os.PathLike, results: Results,
                  command_line: str | None = None) -> Path:
    """Write ``results`` to ``path`` atomically: the HDF5 image is built in memory, written
    to a temporary file in the same folder, flushed to disk, then renamed into place. A full
    disk or another I/O error raises a plain ``OSError`` and leaves neither a partial file nor
    the temporary one (HDF5 itself is never asked to write to a failing disk: a library
    error there can crash the process).

    ``command_line``: what the root attribute ``command_line`` records (default: the one
    given to :func:`set_command_line`, else ``sys.argv``; a file read back keeps its own).
    Every dataset gets ``units`` and ``description`` (:func:`demstudy.io.fields.field_info`,
    overridden by ``results.dataset_attrs``)."""
    path = Path(path)
    if results.skipped and results.path is not None and \
            Path(results.path).resolve() == path.resolve():
        raise ValueError(f"{path}: these results were read without "
                         f"{', '.join(results.skipped)}; writing them back would drop those "
                         "groups (read the whole file)")
    path.parent.mkdir(parents=True, exist_ok=True)
    image = io.BytesIO()
    attrs = root_attrs(results, command_line)
    dim = _dim(attrs)
    extra = results.dataset_attrs
    with h5py.File(image, "w") as f:
        write_attrs(f, attrs)
        _write_group(f.create_group("timeseries"), results.timeseries, {}, extra, dim)
        if results.profiles:
            _write_group(f.create_group("profiles"), results.profiles, results.profile_attrs,
                         extra, dim)
        if results.frames:
            _write_group(f.create_group("frames"), results.frames, {}, extra, dim)
        for name, data in results.groups.items():
            _write_group(f.require_group(name), data, results.group_attrs.get(name, {}),
                         extra, dim)
    write_atomically(path, image.getbuffer())
    results.path = path
    return path


def write_atomically(path: Path, data: bytes | memoryview) -> None:
    """``data`` to ``path`` via a temporary file in the same folder, fsync and rename: the file
    is whole or absent (the temporary file is removed on any error)."""
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except OSError as err:  # say which file (a failed write names none)
        raise OSError(err.errno, f"cannot write {path}: {err.strerror}") from err
    finally:
        if tmp.exists():
            tmp.unlink()


def read_results(path: str | os.PathLike, skip: tuple[str, ...] = ()) -> Results:
    """Read a results file written by any engine; ``skip``: top-level groups not to read
    (e.g. ``("frames", "collisions")``, the large ones, when only the figures are wanted).
    Attributes come back with the types they were written with (module doc).

    A missing, truncated or damaged file (h5py's OSError, KeyError, …, e.g. a zeroed tail)
    raises :class:`~demstudy.errors.BadInputFile` naming the file and h5py's reason."""
    from ..errors import BadInputFile

    if not Path(path).is_file():
        raise BadInputFile(f"results file {path}: no such file")
    try:
        return _read_results(path, skip)
    except (OSError, KeyError, ValueError, RuntimeError, TypeError) as exc:
        # everything is read inside the h5py.File block, so damage anywhere surfaces here
        raise BadInputFile(f"results file {path} is damaged or not a demstudy results file "
                           f"({type(exc).__name__}: {exc})") from exc


def _read_results(path: str | os.PathLike, skip: tuple[str, ...]) -> Results:
    with h5py.File(path, "r") as f:
        res = Results(attrs=read_attrs(f), path=Path(path),
                      skipped=tuple(name for name in skip if name in f))

        def datasets(group: h5py.Group) -> dict[str, np.ndarray]:
            out = {}
            for k, v in group.items():
                if isinstance(v, h5py.Dataset):
                    out[k] = v[()]
                    res.dataset_attrs[v.name.lstrip("/")] = read_attrs(v)
            return out

        def load(name: str) -> dict[str, np.ndarray]:
            if name not in f or name in skip:
                return {}
            return datasets(f[name])

        res.timeseries, res.profiles = load("timeseries"), load("profiles")
        res.frames = load("frames") or None
        if "profiles" in f:
            res.profile_attrs = read_attrs(f["profiles"])

        def collect(group: h5py.Group) -> None:
            found = datasets(group)
            if found:
                key = group.name.lstrip("/")
                res.groups[key] = found
                res.group_attrs[key] = read_attrs(group)
            for item in group.values():
                if isinstance(item, h5py.Group):
                    collect(item)

        for name, item in f.items():
            if (name not in ("timeseries", "profiles", "frames", *skip)
                    and isinstance(item, h5py.Group)):
                collect(item)
    return res


def frames_of(results: Results, dim: int) -> Iterator[Frame]:
    """The frames stored in a results file (``--keep-frames``), as ``Frame`` objects."""
    fr = results.frames
    if not fr or "box_lo" not in fr:
        from ..errors import StatisticUnavailable

        raise StatisticUnavailable("the results file holds no frames with their box: run "
                                   "with --keep-frames (or measure.keep_frames = true)")
    walls = _frame_walls(results)
    for i, t in enumerate(fr["time"]):
        frame = Frame(time=float(t), box_lo=fr["box_lo"][i], box_hi=fr["box_hi"][i],
                      position=fr["position"][i][:, :dim], velocity=fr["velocity"][i][:, :dim],
                      angular_velocity=fr["angular_velocity"][i], radius=fr["radius"][i],
                      tilt=float(fr["tilt"][i]) if "tilt" in fr else 0.0)
        if walls is not None:  # walls that move (servo): where they were at this frame
            frame.extra[WALLS] = (float(walls[i, 0]), float(walls[i, 1]))
        yield frame


def _frame_walls(results: Results) -> np.ndarray | None:
    """(n_frames, 2) wall positions (lower, upper) at the stored frames: ``/frames/walls``,
    or for files written before it the servo's ``/timeseries/wall_position_*`` at the frame
    times (the frames are samples of the time series); None when the walls do not move."""
    fr, ts = results.frames, results.timeseries
    if "walls" in fr:
        walls = np.asarray(fr["walls"], float).reshape(-1, 2)
        if len(walls) == len(fr["time"]):
            return walls
        # shorter: a run resumed from a checkpoint written before frames kept their walls;
        # the servo's time series covers every frame
    if not {"wall_position_lower", "wall_position_upper", "time"} <= set(ts):
        return None
    t = np.asarray(ts["time"], float)
    frame_t = np.asarray(fr["time"], float)
    return np.column_stack([np.interp(frame_t, t, np.asarray(ts[f"wall_position_{side}"],
                                                             float))
                            for side in ("lower", "upper")])
