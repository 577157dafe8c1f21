"""Wall-relative strips (Campbell's ST = HGT/FND) for walls that move: synthetic layered
frames between oscillating walls, fixed walls unchanged, stored frames carrying their walls,
and a real servo run of the event-driven engine through the simulation loop.

Dimensionless particle units: d = 1, m = 1; no gravity, the upper wall's speed U_T = 1 sets
the time scale of the servo run.
"""

from __future__ import annotations

import numpy as np
import pytest

from demstudy.analysis.profiles import ProfileAnalysis
from demstudy.analysis.structure import StructureDistributions
from demstudy.analysis.vdf import VelocityDistribution
from demstudy.analysis.walls import WALLS, frame_walls, with_walls
from demstudy.io.frames import Frame
from demstudy.io.results import Results, frames_of, read_results

N_STRIPS, WIDTH, RADIUS, PER_LAYER = 10, 20.0, 0.2, 8
LAYERS = (0, 3, 6, 9)  # strips holding a layer; the others stay empty


def wall_positions(n_frames: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """Both walls oscillate (amplitudes 0.8 and 0.6 d, out of phase): the gap breathes by
    about ±1 d around 10 d."""
    phase = 2 * np.pi * np.arange(n_frames) / 10.0
    return 0.8 * np.sin(phase), 10.0 + 0.6 * np.sin(phase + 1.3)


def layered_frames(lower: np.ndarray, upper: np.ndarray) -> list[Frame]:
    """Layers of discs riding with the walls at the middle of strips ``LAYERS`` of the gap
    (y = y_lower + (k + ½) H(t)/n), layer k moving at u = k; radius 0.2 < half the narrowest
    strip, so each layer lies inside its wall-relative strip at every frame."""
    x = (np.arange(PER_LAYER) + 0.5) * WIDTH / PER_LAYER
    frames = []
    for t, (lo, hi) in enumerate(zip(lower, upper, strict=True)):
        pos = np.concatenate([np.column_stack([x, np.full(PER_LAYER, lo + (k + 0.5) * (hi - lo)
                                                          / N_STRIPS)]) for k in LAYERS])
        vel = np.zeros_like(pos)
        vel[:, 0] = np.repeat(np.asarray(LAYERS, float), PER_LAYER)
        n = pos.shape[0]
        frame = Frame(float(t), np.array([0.0, lo]), np.array([WIDTH, hi]), pos, vel,
                      np.zeros((n, 1)), np.full(n, RADIUS))
        frames.append(with_walls(frame, lo, hi))
    return frames


def test_wall_relative_profile_keeps_layers_sharp_and_fixed_strips_smear_them():
    lower, upper = wall_positions()
    frames = layered_frames(lower, upper)
    rel = ProfileAnalysis(bin_width=1.0, wall_relative=True).run(frames)
    mean_lo, mean_hi = lower.mean(), upper.mean()
    # the grid between the mean walls, n from the first gap (10.58 d: 11) unless asked
    assert rel.n_bins == round(upper[0] - lower[0]) == 11
    rel = ProfileAnalysis(bin_width=1.0, wall_relative=True, strips=N_STRIPS).run(frames)
    np.testing.assert_allclose(rel.results["edges"],
                               np.linspace(mean_lo, mean_hi, N_STRIPS + 1), rtol=0, atol=1e-12)
    # each layer's solid fraction, frame by frame its discs over the frame's strip
    strip = (upper - lower) / N_STRIPS
    expected = np.mean(PER_LAYER * np.pi * RADIUS**2 / (strip * WIDTH))
    nu = rel.results["solid_fraction"]
    layered = np.isin(np.arange(N_STRIPS), LAYERS)
    np.testing.assert_allclose(nu[layered], expected, rtol=1e-12)
    assert np.all(nu[~layered] == 0.0)
    np.testing.assert_allclose(rel.results["velocity"][layered, 0], LAYERS, rtol=1e-12)
    np.testing.assert_allclose(rel.results["temperature"][layered], 0.0, atol=1e-12)
    assert rel.attrs["wall_relative"] is True and "ST = HGT/FND" in rel.attrs["bins"]
    assert rel.attrs["gap_mean"] == pytest.approx(mean_hi - mean_lo, rel=1e-12)
    # the same frames in strips fixed between the mean walls: the wall strip is empty part
    # of the time and the layers leak into the strips between them
    fixed = ProfileAnalysis(bin_width=1.0, lo=mean_lo, hi=mean_hi).run(frames)
    assert fixed.n_bins == N_STRIPS and fixed.attrs["wall_relative"] is False
    nu_fixed = fixed.results["solid_fraction"]
    assert nu_fixed[0] < 0.8 * nu[0] and nu_fixed[-1] < 0.8 * nu[-1]
    assert nu_fixed[~layered].sum() > 0.2 * expected


def test_wall_relative_vdf_counts_each_layer_in_its_strip():
    lower, upper = wall_positions()
    frames = layered_frames(lower, upper)
    rel = VelocityDistribution(dim=2, wall_relative=True,
                               bin_width=(upper[0] - lower[0]) / N_STRIPS).run(frames)
    assert rel.n_bins == N_STRIPS
    layered = np.isin(np.arange(N_STRIPS), LAYERS)
    count = rel.results["count"]
    np.testing.assert_allclose(count[layered], PER_LAYER, rtol=1e-12)  # per frame
    assert np.all(count[~layered] == 0)
    np.testing.assert_allclose(rel.results["mean"][layered, 0], LAYERS, rtol=1e-12)
    np.testing.assert_allclose(rel.results["edges"],
                               np.linspace(lower.mean(), upper.mean(), N_STRIPS + 1), atol=1e-12)
    assert rel.attrs["wall_relative"] is True
    fixed = VelocityDistribution(dim=2, edges=rel.results["edges"]).run(frames)
    assert fixed.results["count"][~layered].sum() > 0.1 * count.sum()


def test_fixed_walls_give_the_fixed_strip_results():
    """Walls that stand still: strips between them are the fixed strips, to round-off."""
    rng = np.random.default_rng(3)
    frames = []
    for t in range(30):
        n = 200
        pos = np.column_stack([rng.uniform(0, 8, n), rng.uniform(0.5, 9.5, n),
                               rng.uniform(0, 8, n)])
        vel = rng.normal(size=(n, 3)) + np.column_stack([0.1 * pos[:, 1], np.zeros((n, 2))])
        frame = Frame(float(t), np.zeros(3), np.array([8.0, 10.0, 8.0]), pos, vel,
                      rng.normal(size=(n, 3)), rng.uniform(0.4, 0.5, n))
        frames.append(with_walls(frame, 0.0, 10.0))
    fixed = ProfileAnalysis(bin_width=1.0, lo=0.0, hi=10.0, dim=3, z_cells=2).run(frames)
    rel = ProfileAnalysis(bin_width=1.0, dim=3, z_cells=2, wall_relative=True).run(frames)
    assert fixed.results.keys() == rel.results.keys()
    for key, value in fixed.results.items():
        np.testing.assert_allclose(rel.results[key], value, rtol=1e-12, atol=1e-14,
                                   err_msg=key)
    vdf_fixed = VelocityDistribution(dim=3, edges=fixed.results["edges"]).run(frames)
    vdf_rel = VelocityDistribution(dim=3, wall_relative=True).run(frames)
    for key, value in vdf_fixed.results.items():
        np.testing.assert_allclose(vdf_rel.results[key], value, rtol=1e-12, atol=1e-14,
                                   err_msg=key)


def test_wall_relative_needs_the_frames_walls_and_a_bounded_y():
    lower, upper = wall_positions(2)
    frame = layered_frames(lower, upper)[0]
    del frame.extra[WALLS]
    with pytest.raises(ValueError, match=r"frame.extra\['walls'\]"):
        ProfileAnalysis(wall_relative=True).run([frame])
    with pytest.raises(ValueError, match="axis y without a period"):
        ProfileAnalysis(wall_relative=True, period=10.0)
    with pytest.raises(ValueError, match="strips = 0"):
        ProfileAnalysis(wall_relative=True, strips=0)


def test_structure_mid_plane_follows_the_walls():
    lower, upper = wall_positions()
    frames = layered_frames(lower, upper)
    ana = StructureDistributions(dim=2, r_max=4.0, half_width=1.0, y_mid=0.0,
                                 wall_relative=True).run(frames)
    assert ana.attrs["y_mid"] == pytest.approx(0.5 * (lower + upper).mean(), rel=1e-12)
    # the layer nearest the mid-plane (strip 6 at 0.65 H: 1.5 strips from the middle) is
    # outside |y - y_mid| < 1 and no disc is a test particle: only a wider region finds it
    wide = StructureDistributions(dim=2, r_max=4.0, half_width=1.6, wall_relative=True)
    assert np.nansum(wide.run(frames).results["parallel"]) > 0


def test_stored_frames_carry_their_walls():
    lower, upper = wall_positions(6)
    frames = layered_frames(lower, upper)
    stored = {k: np.stack([getattr(f, k) for f in frames]) for k in
              ("position", "velocity", "angular_velocity", "radius", "box_lo", "box_hi")}
    stored["time"] = np.array([f.time for f in frames])
    # older files: the walls come from the servo's time series at the frame times (samples
    # at every half time unit, the frames at every other one)
    t = np.arange(0, 6, 0.5)
    ts = {"time": t, "wall_position_lower": np.interp(t, stored["time"], lower),
          "wall_position_upper": np.interp(t, stored["time"], upper)}
    res = Results({}, ts, {}, {}, stored)
    got = np.array([frame_walls(f) for f in frames_of(res, 2)])
    np.testing.assert_allclose(got, np.column_stack([lower, upper]), rtol=0, atol=1e-12)
    stored["walls"] = np.column_stack([lower, upper]) + 1.0  # /frames/walls wins
    got = np.array([frame_walls(f) for f in frames_of(res, 2)])
    np.testing.assert_allclose(got, np.column_stack([lower, upper]) + 1.0, atol=1e-12)
    del stored["walls"]
    res.timeseries = {"time": t}  # fixed walls: nothing attached
    assert all(frame_walls(f) is None for f in frames_of(res, 2))


def test_servo_run_bins_between_its_moving_walls(tmp_path):
    """A short event-driven run of Campbell's servo Couette cell (40 rough discs, both walls
    under the servo, σ_n = 10 × Campbell's): its profiles and vdf say wall-relative, their
    wall strips hold particles, the stored frames carry the walls the servo recorded, and a
    re-analysis of the stored frames gives the run's own profiles."""
    from demstudy.scene import load_scene
    from demstudy.simulation import RunOptions, run_scene

    sets = [f"walls.{k}.servo.{key}={value}" for k in (0, 1)
            for key, value in (("normal_stress", 0.039375), ("interval_collisions", 3),
                               ("clamp", "false"))]
    sets += ["run.equilibration=100", "run.production=150",
             'measure.statistics=["profiles", "vdf", "structure"]']
    scene = load_scene("inputs/campbell1982/couette-rough.toml", sets)
    out = run_scene(scene, "edmd", RunOptions(out=tmp_path / "servo.h5", progress=False,
                                              keep_frames=True, plan=False))
    res = read_results(out)
    ts, prof, attrs = res.timeseries, res.profiles, res.profile_attrs
    production = ts["time"] > res.attrs["equilibration_end"] + 1e-9
    walls = np.column_stack([ts["wall_position_lower"][production],
                             ts["wall_position_upper"][production]])
    assert np.ptp(walls[:, 0]) > 0.05  # the walls do move
    np.testing.assert_array_equal(res.frames["walls"], walls)
    assert attrs["wall_relative"] is True and "ST = HGT/FND" in attrs["bins"]
    np.testing.assert_allclose([attrs["lo"], attrs["hi"]], walls.mean(axis=0), rtol=1e-12)
    assert attrs["n_bins"] == round(walls[0, 1] - walls[0, 0])
    assert prof["solid_fraction"][0] > 0.2 and prof["solid_fraction"][-1] > 0.2
    vdf = res.groups["statistics/vdf"]
    assert res.group_attrs["statistics/vdf"]["wall_relative"] is True
    np.testing.assert_allclose(vdf["edges"], prof["edges"], rtol=1e-12)
    assert vdf["count"][0] > 0 and vdf["count"][-1] > 0
    assert res.group_attrs["statistics/structure"]["mid_plane"].startswith("between")
    again = read_results(out).analyze("profiles", save=False)
    for key in ("solid_fraction", "velocity", "temperature", "edges"):
        np.testing.assert_allclose(again.profiles[key], prof[key], rtol=1e-12, err_msg=key)
    fixed = read_results(out).analyze("profiles", save=False, wall_relative=False)
    assert fixed.profile_attrs["wall_relative"] is False  # where production started
    np.testing.assert_allclose(fixed.profiles["edges"][[0, -1]], walls[0], rtol=1e-12)


def test_frames_without_walls_fall_back_to_fixed_strips_with_a_warning():
    """A servo scene's frames written without wall positions (older or hand-made files):
    re-analysis warns and uses fixed strips at the scene's walls instead of failing; frames
    that carry walls keep the wall-relative default."""
    from demstudy.analysis.walls import strips_for
    from demstudy.scene import load_scene

    scene = load_scene("campbell1982/couette-noslip")  # servo walls
    bare = Frame(time=0.0, box_lo=np.zeros(2), box_hi=np.array([4.8, 12.0]),
                 position=np.array([[1.0, 6.0]]), velocity=np.zeros((1, 2)),
                 angular_velocity=np.zeros((1, 1)), radius=np.array([0.5]))
    with pytest.warns(UserWarning, match="no wall positions"):
        assert strips_for(scene, lambda: [bare], None) is False
    walled = with_walls(bare, 0.0, 12.0)
    assert strips_for(scene, lambda: [walled], None) is None
    assert strips_for(scene, lambda: [bare], True) is True  # asked: the error comes later


def test_checkpointed_analyses_from_before_wall_strips_resume_on_fixed_strips():
    """Analyses pickled into a checkpoint before wall-relative strips existed lack the new
    attributes; they resume as they were built (fixed strips), not with AttributeError."""
    import pickle

    frame = Frame(time=0.0, box_lo=np.zeros(2), box_hi=np.array([4.0, 10.0]),
                  position=np.array([[1.0, 3.0], [2.0, 6.0]]), velocity=np.zeros((2, 2)),
                  angular_velocity=np.zeros((2, 1)), radius=np.full(2, 0.5))
    for analysis in (ProfileAnalysis(dim=2, lo=0.0, hi=10.0),
                     StructureDistributions(dim=2, r_max=2.0, dr=0.5, half_width=1.0),
                     VelocityDistribution(dim=2, edges=np.linspace(0.0, 10.0, 3))):
        analysis.feed(frame)
        old = pickle.loads(pickle.dumps(analysis))
        for name in ("walls", "_y_mid_sum"):
            old.__dict__.pop(name, None)  # what an older pickle holds
        old.feed(frame)
        assert old.n_frames == 2
    structure = pickle.loads(pickle.dumps(StructureDistributions(dim=2, r_max=2.0, dr=0.5,
                                                                 half_width=1.0, y_mid=5.0)))
    structure.feed(frame)
    structure.__dict__.pop("_y_mid_sum")
    structure.feed(frame)
    structure.finish()
    assert structure.attrs["y_mid"] == pytest.approx(5.0)
