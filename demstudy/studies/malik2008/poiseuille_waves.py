"""Whether a run holds Malik's S-shaped density wave (Fig 4.5; digest §4.10-4.11: the birth of
the (k_x, k_y) = (1, 1) mode of the xy density marks the plug → S-wave transition).

Per kept frame the particle counts in 10 × 10 cells of the xy plane (depth-averaged over z)
are Fourier transformed; |X(k)|² of independent particles averages N (shot noise), so the
ratio R = <|X(1, ±1)|²> / N is 1 without structure and ≫ 1 with an S-wave. The error is the
standard error over frames (frames several collision times apart).
Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...io.results import read_results
from ..records import derived
from .poiseuille_data import FlowData

CELLS = 10


def mode_ratios(d: FlowData) -> dict[str, tuple[float, float]]:
    """R (mean, error) of the modes (1, ±1) (S-wave), (1, 0) (slug) and (0, 1) (plug): as a
    study record keeps them, or from the run's frames."""
    kept = derived(d.res.groups, "mode_ratios")
    if kept is not None:
        return {k: (float(v[0]), float(v[1])) for k, v in kept.items()}
    return frame_mode_ratios(d.path)


def frame_mode_ratios(path: Path) -> dict[str, tuple[float, float]]:
    """``mode_ratios`` from the frames of the results file at ``path``."""
    full = read_results(path, skip=("collisions",))
    size = full.scene.box.size
    per_frame: dict[str, list[float]] = {"11": [], "10": [], "01": []}
    for frame in full.iter_frames():
        x = np.mod(frame.position[:, 0], size[0])
        y = np.clip(frame.position[:, 1], 0, size[1] - 1e-9)
        counts, _, _ = np.histogram2d(x, y, bins=CELLS, range=[[0, size[0]], [0, size[1]]])
        spec = np.abs(np.fft.fft2(counts)) ** 2 / x.size
        per_frame["11"].append(0.5 * (spec[1, 1] + spec[1, -1]))
        per_frame["10"].append(spec[1, 0])
        per_frame["01"].append(spec[0, 1])
    out = {}
    for key, values in per_frame.items():
        v = np.asarray(values)
        out[key] = (float(v.mean()) if v.size else float("nan"),
                    float(v.std(ddof=1) / np.sqrt(v.size)) if v.size > 1 else float("nan"))
    return out


def s_wave_text(r: dict[str, tuple[float, float]]) -> str:
    """The three modes of ``mode_ratios`` as the report shows them."""
    text = ", ".join(f"R{k} = {m:.3g} ± {e:.2g}" for k, (m, e) in
                     (("(1,±1) S-wave", r["11"]), ("(1,0) slug", r["10"]),
                      ("(0,1) plug", r["01"])))
    return text + (" (R(k_x, k_y) = |FFT of the xy cell counts at that mode|² / N, the "
                   "(1, 1) and (1, -1) modes averaged; shot noise of independent particles "
                   "= 1)")


#: a plug: the x-modulated modes (1, 0) and (1, ±1) hold less than this share of the (0, 1)
#: mode (the density profile across the walls, strong in every wall-bounded flow)
PLUG_SHARE = 0.01


def structure_class(r: dict[str, tuple[float, float]]) -> tuple[str, str]:
    """(class, why) of a channel flow from its three modes (``mode_ratios``), Malik's
    taxonomy (digest §4.11) cut down to what they tell: "plug" when (1, 0) and (1, ±1) lie
    below ``PLUG_SHARE`` of (0, 1) or within 2σ of the shot noise (1) (the density varies
    across y only); else "s-wave" when (1, ±1) beats (1, 0) beyond 2σ (the antisymmetric
    mode whose birth marks plug → S-wave), "slug" when (1, 0) beats (1, ±1), "mixed"
    (slug + S-wave, Malik's "sandwich") when neither does."""
    (s, es), (g, eg), (p, _ep) = r["11"], r["10"], r["01"]
    top = max(s, g)
    if top < PLUG_SHARE * p or max(s - 2 * es, g - 2 * eg) <= 1.0:
        return "plug", (f"(1, 0) and (1, ±1) at {100 * top / p:.2g} % of (0, 1)'s power: the "
                        "density varies across y only")
    modulated = (f"x-modulated ((1, 0) and (1, ±1) up to {100 * top / p:.2g} % of (0, 1)'s "
                 f"power, {100 * (top / p) ** 0.5:.2g} % of its amplitude)")
    if s - g > 2 * float(np.hypot(es, eg)):
        return "s-wave", f"{modulated}, (1, ±1) above (1, 0) beyond 2σ"
    if g - s > 2 * float(np.hypot(es, eg)):
        return "slug", f"{modulated}, (1, 0) above (1, ±1) beyond 2σ"
    return "mixed", f"{modulated}, (1, 0) and (1, ±1) equal within 2σ (slug + S-wave)"
