"""Files of the engine map (``engine_map.csv``, ``engine_map.json``, both written atomically,
and ``engine_map.png``), the machine that measured it, and reading a map back for one scene
(``map_hint``: what ``demstudy cost`` prints after its recommendation).

Dimensionless particle units: d = 1, m = 1, the shear rate γ̇ = 1 sets the time scale; costs
in wall seconds of the machine named in the files, per particle per strain unit (1/γ̇).
"""

from __future__ import annotations

import csv
import dataclasses
import datetime
import io
import json
import math
import os
from pathlib import Path

from .. import UNITS_NOTE
from ..io.results import write_atomically

COLUMNS = ("dim", "fraction", "restitution", "fraction_actual", "particles", "box", "cheaper",
           "cost_ratio", "log10_ratio", "log10_ratio_err", "break_even_R", "event_cost",
           "soft_cost", "collision_rate", "tau_flight", "temperature", "kn", "kstar", "tc",
           "dt", "soft_steps", "soft_strain", "soft_extrapolated", "event_strain",
           "event_equilibration", "event_wall_seconds", "soft_wall_seconds", "events",
           "elastic_tc_collisions", "tc_share", "ratio_R", "repeats", "impractical", "seconds")
COST_UNITS = ("costs: wall seconds per particle per strain unit (1/gamma_dot) on the machine "
              "named; cost_ratio = soft_cost / event_cost")
METHOD = ("each point measured `repeats` times (seeds 1, 2, ...; medians; cost_ratio the "
          "geometric mean of the repeats' ratios, log10_ratio_err its standard error); "
          "event-driven: edmd (TC model, default t_c), equilibration 3 temperature relaxation "
          "times and production 400 collisions per particle (from Enskog's rate at T = 1; "
          "2-200 strain units), cost = production share of wall time / (N strain); "
          "impractical when it times out, fails or its TC model made > 10 % of the "
          "production's collisions elastic; soft: LAMMPS Hooke, t_c = R tau_flight "
          "(tau_flight = 1 / collision rate per particle of the edmd production), 50 steps per "
          "contact, cost = wall / (N strain) of a run of soft_steps time steps started at the "
          "edmd temperature (soft_extrapolated: they cover < soft_strain strain units); "
          "break_even_R = R cost_ratio: the t_c/tau_flight at which soft would cost the same")
#: where ``demstudy cost`` looks for a map: the results folder, then the one in the docs
MAP_PLACES = (Path("results") / "engine-map" / "engine_map.json",
              Path(__file__).resolve().parents[2] / "docs" / "data" / "engine_map.json")


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    import platform

    return platform.processor() or "unknown"


def machine_note(end: bool = False) -> dict:
    """The machine (CPU model, cores, date, load average) at the start, or (``end``) the
    load at the end and whether other work loaded it (load above half the cores)."""
    load = os.getloadavg()[0]
    cores = os.cpu_count() or 1
    if end:
        return {"load_end": load, "finished": datetime.datetime.now(datetime.UTC).isoformat(
            timespec="seconds")}
    return {"cpu": _cpu_model(), "cores": cores, "load_start": load,
            "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")}


def loaded_note(machine: dict) -> str:
    worst = max(machine.get("load_start", 0.0), machine.get("load_end", 0.0))
    if worst > 0.5 * machine.get("cores", 1):
        return (f"the machine was loaded by other work (load average up to {worst:.1f} on "
                f"{machine.get('cores')} cores): absolute costs are inflated, the ratios less")
    return "the machine was otherwise idle"


def _clean(value):
    return None if isinstance(value, float) and not math.isfinite(value) else value


def summary(result) -> dict:
    machine = dict(result.machine)
    machine["note"] = loaded_note(machine)
    return {"units": UNITS_NOTE + "; " + COST_UNITS, "method": METHOD,
            "settings": dataclasses.asdict(result.settings) | {
                "particles": {str(k): v for k, v in result.settings.particles.items()}},
            "machine": machine,
            "points": [{k: _clean(v) for k, v in row.items()} for row in result.rows]}


def write_map(result, figure: bool = True) -> list[Path]:
    """engine_map.csv and engine_map.json (atomically) and engine_map.png in its folder."""
    folder = result.folder
    folder.mkdir(parents=True, exist_ok=True)
    data = summary(result)
    buffer = io.StringIO()
    buffer.write(f"# {UNITS_NOTE}; {COST_UNITS}\n# method: {METHOD}\n"
                 f"# machine: {data['machine']['cpu']}, {data['machine']['date']}; "
                 f"{data['machine']['note']}\n")
    writer = csv.DictWriter(buffer, COLUMNS, extrasaction="ignore")
    writer.writeheader()
    for row in result.rows:
        writer.writerow(row)
    written = [folder / "engine_map.csv", folder / "engine_map.json"]
    write_atomically(written[0], buffer.getvalue().encode())
    write_atomically(written[1], json.dumps(data, indent=1).encode())
    if figure:
        from .map_figure import map_figure

        written.append(map_figure(data, folder / "engine_map.png"))
    return written


def read_map(path: str | os.PathLike | None = None) -> dict | None:
    """The map's JSON summary from ``path``, else from the first of ``MAP_PLACES`` that
    exists (None when none does)."""
    places = [Path(path)] if path is not None else list(MAP_PLACES)
    for place in places:
        if place.is_file():
            return json.loads(place.read_text())
    return None


def nearest_point(data: dict, dim: int, fraction: float, e: float) -> dict | None:
    """The map's point of dimension ``dim`` nearest to (fraction, e), each axis scaled by its
    grid range, so that both count alike."""
    points = [p for p in data["points"] if p["dim"] == dim]
    if not points:
        return None
    span_f = (max(p["fraction"] for p in points) - min(p["fraction"] for p in points)) or 1.0
    span_e = (max(p["restitution"] for p in points)
              - min(p["restitution"] for p in points)) or 1.0
    return min(points, key=lambda p: ((p["fraction"] - fraction) / span_f) ** 2
               + ((p["restitution"] - e) / span_e) ** 2)


def map_hint(scene, path: str | os.PathLike | None = None) -> str | None:
    """One line for ``scene`` from the engine map (nearest grid point of its dimension), or
    None without a map. Only Lees–Edwards shear was mapped: other flows are told so."""
    data = read_map(path)
    if data is None:
        return None
    point = nearest_point(data, scene.dimension, scene.solid_fraction,
                          scene.contact.restitution)
    if point is None:
        return None
    kind = "" if scene.shear is not None else " (mapped in Lees-Edwards shear, not this flow)"
    what = (f"soft/event-driven cost {point['cost_ratio']:.3g}" if point.get("cost_ratio")
            else point.get("impractical") or "")
    return (f"engine map{kind}: nearest point {point['dim']}D fraction {point['fraction']:g}, "
            f"e = {point['restitution']:g}: {point['cheaper']} ({what}; R = "
            f"{point['ratio_R']:g}, {data['machine'].get('date', '')[:10]})")
