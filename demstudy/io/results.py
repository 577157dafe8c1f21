"""The results file: one HDF5 layout for every engine (see docs/results-format.md).

Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (otherwise a wall speed
or the shear rate sets the time scale); the root attribute ``units`` says so in every file.
Writes are atomic: the file is built in memory, written under a temporary name, flushed
and renamed into place.
"""

from __future__ import annotations

import datetime as _dt
import io
import os
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from .. import UNITS_NOTE, __version__
from .frames import Frame

FORMAT_VERSION = 1


@dataclass
class Results:
    """In-memory content of a results file."""

    attrs: dict[str, Any]
    timeseries: dict[str, np.ndarray] = field(default_factory=dict)
    profiles: dict[str, np.ndarray] = field(default_factory=dict)
    profile_attrs: dict[str, Any] = field(default_factory=dict)
    frames: dict[str, np.ndarray] | None = None
    groups: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    group_attrs: dict[str, dict[str, Any]] = field(default_factory=dict)


def _write_group(group: h5py.Group, data: Mapping[str, Any], attrs: Mapping[str, Any] = {}) -> None:
    for name, value in data.items():
        arr = np.asarray(value)
        kwargs = {"compression": "gzip", "compression_opts": 4} if arr.size > 4096 else {}
        group.create_dataset(name, data=arr, **kwargs)
    for key, value in attrs.items():
        group.attrs[key] = value


def write_results(path: str | os.PathLike, results: Results) -> Path:
    """Write ``results`` to ``path`` atomically: the HDF5 image is built in memory, written
    to a temporary file in the same folder, flushed to disk, then renamed into place. A full
    disk or another I/O error raises a plain ``OSError`` and leaves neither a partial file nor
    the temporary one (HDF5 itself is never asked to write to a failing disk: a library
    error there can crash the process)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    image = io.BytesIO()
    with h5py.File(image, "w") as f:
        attrs = {
            "format_version": FORMAT_VERSION,
            "demstudy_version": __version__,
            "units": UNITS_NOTE,
            "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
            **results.attrs,
        }
        for key, value in attrs.items():
            f.attrs[key] = value
        _write_group(f.create_group("timeseries"), results.timeseries)
        if results.profiles:
            _write_group(f.create_group("profiles"), results.profiles, results.profile_attrs)
        if results.frames:
            _write_group(f.create_group("frames"), results.frames)
        for name, data in results.groups.items():
            _write_group(f.require_group(name), data, results.group_attrs.get(name, {}))
    write_atomically(path, image.getbuffer())
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
    (e.g. ``("frames", "collisions")``, the large ones, when only the figures are wanted)."""
    def decode(value: Any) -> Any:
        return value.decode() if isinstance(value, bytes) else value

    with h5py.File(path, "r") as f:
        def load(name: str) -> dict[str, np.ndarray]:
            if name not in f or name in skip:
                return {}
            return {k: v[()] for k, v in f[name].items() if isinstance(v, h5py.Dataset)}

        res = Results(attrs={k: decode(v) for k, v in f.attrs.items()},
                      timeseries=load("timeseries"), profiles=load("profiles"),
                      frames=load("frames") or None)
        if "profiles" in f:
            res.profile_attrs = {k: decode(v) for k, v in f["profiles"].attrs.items()}

        def collect(group: h5py.Group) -> None:
            datasets = {k: v[()] for k, v in group.items() if isinstance(v, h5py.Dataset)}
            if datasets:
                key = group.name.lstrip("/")
                res.groups[key] = datasets
                res.group_attrs[key] = {k: decode(v) for k, v in group.attrs.items()}
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
        raise ValueError("the results file holds no frames with their box: run with "
                         "--keep-frames (or measure.keep_frames = true)")
    for i, t in enumerate(fr["time"]):
        yield Frame(time=float(t), box_lo=fr["box_lo"][i], box_hi=fr["box_hi"][i],
                    position=fr["position"][i][:, :dim], velocity=fr["velocity"][i][:, :dim],
                    angular_velocity=fr["angular_velocity"][i], radius=fr["radius"][i],
                    tilt=float(fr["tilt"][i]) if "tilt" in fr else 0.0)
