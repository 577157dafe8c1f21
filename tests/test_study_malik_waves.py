"""The density-wave part of ``demstudy study malik2008`` (Malik 2008, Ch. 5): its cases are
the thesis's boxes exactly, the classifier gives the classes of analytic density fields, and
a study without its runs reports "not run" instead of failing.

Dimensionless particle units: d = 1, m = 1, g = 1 (gravity acts).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from demstudy.io.frames import Frame
from demstudy.studies.base import NOT_RUN, VERDICTS
from demstudy.studies.malik2008 import STUDY, waves
from demstudy.studies.malik2008.tc import STUDY_TC
from demstudy.studies.malik2008.waves_measure import density_waves
from demstudy.studies.malik2008.waves_report import analyse_waves

#: the thesis's table (digest §1.5): N, L, W, H of every Ch. 5 box
THESIS_TABLE = {(600, 9, 15, 15), (4800, 18, 30, 30), (22000, 30, 50, 50), (1400, 21, 15, 15),
                (10800, 42, 30, 30), (50094, 70, 50, 50), (3000, 45, 15, 15),
                (24000, 90, 30, 30), (107811, 150, 50, 50), (4800, 75, 15, 15),
                (40000, 150, 30, 30), (180000, 250, 50, 50), (21952, 150, 50, 10),
                (323433, 150, 50, 150)}


def _box_of(scene) -> tuple[int, int, int, int]:
    size = tuple(int(round(v)) for v in scene.box.size)
    assert all(math.isclose(v, round(v)) for v in scene.box.size)
    return (scene.particles.count, *size)


def test_cases_are_the_thesis_boxes_with_its_collision_parameters() -> None:
    twins = {waves.twin_name(b) for b in waves.twin_boxes()}
    cases = [c for c in waves.cases(False) if c.name not in twins]
    scenes = {c.name: c.load() for c in cases}  # every scene validates
    e07 = {n: s for n, s in scenes.items() if s.contact.restitution == 0.7}
    assert {_box_of(s) for s in e07.values()} == THESIS_TABLE
    assert len(e07) == len(THESIS_TABLE)
    study = [(_box_of(s), s.contact.restitution) for s in scenes.values()
             if s.contact.restitution != 0.7]
    assert sorted(study) == [((107811, 150, 50, 50), 0.9), ((107811, 150, 50, 50), 0.99)]
    for scene in scenes.values():
        assert scene.contact.tangential.beta == 0.1
        assert [w.restitution for w in scene.walls] == [0.99, 0.99]
        assert [w.tangential.beta for w in scene.walls] == [0.99, 0.99]
        assert tuple(scene.gravity.direction) == (1.0, 0.0, 0.0)
        assert scene.measure.keep_frames
        n, length, width, height = _box_of(scene)
        assert 0.148 < n * math.pi / 6 / (length * width * height) < 0.156  # φ ≈ 0.15


def test_case_names_unique_and_the_wide_boxes_run_over_the_thesis_span() -> None:
    """W = 15 boxes: the shipped scenes as they are; W ≥ 30: the shipped scene over 2000 to
    30000 c/p (c/p = 2 N_pair/N), past the thesis's last snapshot (14000 c/p, or 28000 in the
    N_pair/N reading), with frames through the thesis's window."""
    names = [c.name for c in STUDY.cases(False)]
    assert len(set(names)) == len(names)
    big = [c for c in waves.cases(False) if c.name == "waves-phi0.15-L150W50H50-edmd"]
    assert big and big[0].scene == "malik2008/waves-phi0.15-L150W50H50"
    assert (big[0].engine, dict(big[0].options)) == ("edmd", {"tc": 1e-5})  # the study's t_c
    for case in waves.cases(False):
        run = case.load().run
        if "W15" in case.name:
            assert case.sections == {} and run.unit == "time"
            continue
        assert run.unit == "collisions"
        assert 2 * run.equilibration <= 4000  # frames before the thesis's first snapshot
        assert 28000 <= 2 * (run.equilibration + run.production) <= 40000
        assert 2 * run.sample_interval <= 1000  # snapshots at 10000, 11000 c/p apart
    for case in waves.cases(False):
        scene = case.load()
        e = "" if scene.contact.restitution == 0.7 else f"-e{scene.contact.restitution:g}"
        tc = f"-tc{case.options['tc']:g}" if case.options["tc"] != STUDY_TC else ""
        n, length, width, height = _box_of(scene)
        assert case.name == f"waves-phi0.15-L{length}W{width}H{height}{e}{tc}-edmd"


@pytest.mark.parametrize("tag", ["L42W30H30", "L90W30H30", "L150W50H10"])
def test_each_tc_twin_is_its_box_at_a_smaller_tc_only(tag: str) -> None:
    """Each TC twin runs its box's scene over the same span, only the engine's t_c smaller
    than the study's (given explicitly: the engine's default for spheres is the twins' 1e-6,
    the study's records were made at 1e-5); no twin is part of --quick."""
    from demstudy.engines.edmd.core import default_tc

    by_name = {c.name: c for c in waves.cases(False)}
    twin = by_name[f"waves-phi0.15-{tag}-tc1e-06-edmd"]
    box = by_name[f"waves-phi0.15-{tag}-edmd"]
    assert dict(twin.options) == {"tc": 1e-6} and 1e-6 < STUDY_TC
    assert twin.load() == box.load() and twin.scene == box.scene
    assert dict(box.options) == {"tc": STUDY_TC} != {"tc": default_tc(box.load().dimension)}
    assert all(c.options == {"tc": STUDY_TC} for c in waves.cases(True))
    assert not any("tc" in c.name for c in waves.cases(True))
    assert sum("-tc" in n for n in by_name) == len(waves.TC_TWINS) == 5


def test_quick_subset_is_small_and_short() -> None:
    quick = waves.cases(True)
    assert 1 <= len(quick) <= 2 and all(c.quick for c in quick)
    for case in quick:
        scene = case.load(quick=True)
        assert scene.box.size[1] == 15 and scene.particles.count <= 3000
        assert scene.run.equilibration + scene.run.production <= 300
        # enough production frames for the halves' stationarity test
        assert scene.run.production / scene.run.sample_interval >= 20


# -- the classifier on analytic density fields -----------------------------------------
SIZE = np.array([45.0, 15.0, 15.0])
Y_LO, Y_HI = 0.5, 14.5
Y_C = 0.5 * (Y_LO + Y_HI)


def _frames(density, n: int = 4000, frames: int = 12, seed: int = 1):
    """Frames of ``n`` centres drawn (rejection) from ``density(x, y)`` (max ≤ 1)."""
    rng = np.random.default_rng(seed)
    for i in range(frames):
        pos = np.empty((0, 3))
        while pos.shape[0] < n:
            trial = rng.uniform([0, Y_LO, 0], [SIZE[0], Y_HI, SIZE[2]], size=(4 * n, 3))
            keep = rng.uniform(size=4 * n) < density(trial[:, 0], trial[:, 1])
            pos = np.vstack([pos, trial[keep]])
        pos = pos[:n]
        yield Frame(time=float(i), box_lo=np.zeros(3), box_hi=SIZE, position=pos,
                    velocity=np.zeros((n, 3)), angular_velocity=np.zeros((n, 3)),
                    radius=np.full(n, 0.5))


def _pattern(density) -> str:
    analysis = density_waves(SIZE)
    return analysis.run(_frames(density)).attrs["pattern"]


def _blob(x, y, x0, y0, sx=4.0, sy=2.0):
    dx = (x - x0 + 0.5 * SIZE[0]) % SIZE[0] - 0.5 * SIZE[0]  # periodic along x
    return np.exp(-0.5 * (dx / sx) ** 2 - 0.5 * ((y - y0) / sy) ** 2)


def test_classifier_plug() -> None:
    # dense core at the centreline, uniform along the flow: Malik's (0, 1)
    assert _pattern(lambda x, y: 0.15 + 0.85 * np.exp(-0.5 * ((y - Y_C) / 2.0) ** 2)) == "plug"


def test_classifier_s_wave() -> None:
    # dense on one side of the centreline facing dilute on the other, alternating along x
    def s_wave(x, y):
        return 0.1 + 0.9 * np.maximum(_blob(x, y, 0.25 * SIZE[0], Y_C + 3.5),
                                      _blob(x, y, 0.75 * SIZE[0], Y_C - 3.5))
    assert _pattern(s_wave) == "s-wave"


def test_classifier_slug() -> None:
    # one dense clump on the centreline, localised along x: (0, 1) + (1, 0)
    assert _pattern(lambda x, y: 0.1 + 0.9 * _blob(x, y, 0.5 * SIZE[0], Y_C, sx=6.0)) == "slug"


def test_classifier_homogeneous_gas_has_no_structure() -> None:
    assert _pattern(lambda x, y: np.ones_like(x)) == "none"


# -- missing runs ----------------------------------------------------------------------
@pytest.mark.parametrize("quick", [True, False])
def test_missing_runs_give_not_run_checks(tmp_path: Path, quick: bool) -> None:
    ana = analyse_waves({}, tmp_path, quick)
    boxes = {c.name for c in waves.cases(quick)} - {waves.twin_name(b)
                                                     for b in waves.twin_boxes()}
    per_box = [c for c in ana.checks if c.ref.startswith("Fig 5.") and "digest §4.11" in c.ref]
    assert len(per_box) == len(boxes)
    assert all(c.verdict == NOT_RUN and "forecast" in c.reason for c in per_box)
    assert all(c.verdict in VERDICTS for c in ana.checks)
    assert not any(c.verdict != NOT_RUN for c in ana.checks)
    assert (tmp_path / "waves-phase-diagram.png").is_file()


def test_unreadable_run_is_not_run(tmp_path: Path) -> None:
    bad = tmp_path / "bad.h5"
    bad.write_bytes(b"not hdf5")
    name = waves.cases(True)[0].name
    ana = analyse_waves({name: bad}, tmp_path, True)
    row = ana.checks[0]
    assert "N = 600" in row.ref
    assert row.verdict == NOT_RUN and "unreadable" in row.reason


def test_spin_up_run_is_not_steady(tmp_path: Path) -> None:
    """A short run of the N = 600 box stops while gravity still accelerates the flow (the KE
    levels off after ≈ 100 √(d/g)): gravity's input exceeds the dissipation, and the steady
    check must say so rather than call it steady."""
    from demstudy.api import run
    from demstudy.scene import load_scene
    from demstudy.studies.base import NOT_REPRODUCED
    from demstudy.studies.malik2008.waves_measure import measure

    case = waves.cases(True)[0]
    scene = load_scene(case.scene, run={"equilibration": 10.0, "production": 16.0,
                                        "sample_interval": 1.0})
    path = tmp_path / f"{case.name}.h5"
    run(scene, engine="edmd", out=path, progress=False)
    measured = measure(path)
    ratio, err = measured.balance
    assert ratio + 2 * err < 1.0  # input > dissipation while the flow accelerates
    assert measured.ke_halves[1][0] > measured.ke_halves[0][0]
    ana = analyse_waves({case.name: path}, tmp_path, True)
    steady = next(c for c in ana.checks if c.ref.startswith("[L1088]"))
    assert steady.verdict == NOT_REPRODUCED
    assert ana.checks[0].verdict != NOT_RUN
    assert (tmp_path / f"{case.name.removesuffix('-edmd')}.png").is_file()


# -- stationarity is judged on the modes, not on the energy ----------------------------
def _synthetic_run(path: Path, second_half, rate: float = 5.0) -> Path:
    """A results file whose energy is flat and balanced (input = dissipation) throughout,
    with 40 production frames: a plug, then ``second_half`` for the last 20; ``rate`` pair
    collisions per particle per time unit (c/p = 2 rate t)."""
    import h5py

    plug = lambda x, y: 0.15 + 0.85 * np.exp(-0.5 * ((y - Y_C) / 2.0) ** 2)  # noqa: E731
    frames = list(_frames(plug, frames=20, seed=2)) + list(_frames(second_half, frames=20,
                                                                   seed=3))
    n = frames[0].n
    t = np.arange(0.0, 61.0)  # equilibration to 20, frames at 21..60
    rng = np.random.default_rng(4)
    with h5py.File(path, "w") as f:
        f.attrs["equilibration_end"] = 20.0
        ts = f.create_group("timeseries")
        ts["time"] = t
        ts["collisions"] = (rate * n * t).astype(np.int64)
        ts["kinetic_energy"] = n * (100.0 + rng.normal(0, 0.5, t.size))
        ts["gravity_work"] = 50.0 * n * t
        ts["dissipated_energy"] = 50.0 * n * t + rng.normal(0, 0.5 * n, t.size)
        fr = f.create_group("frames")
        fr["time"] = t[21:]
        fr["position"] = np.stack([fr_.position for fr_ in frames])
        fr["velocity"] = np.zeros((40, n, 3))
        fr["radius"] = np.full((40, n), 0.5)
        fr["box_lo"] = np.zeros((40, 3))
        fr["box_hi"] = np.tile(SIZE, (40, 1))
    return path


def test_plug_turning_into_slug_is_not_steady_though_energy_is(tmp_path: Path) -> None:
    from demstudy.studies.base import PARTLY, REPRODUCED
    from demstudy.studies.malik2008.waves_boxes import BOXES
    from demstudy.studies.malik2008.waves_measure import measure
    from demstudy.studies.malik2008.waves_report import steady_check

    def slug(x, y):
        return 0.1 + 0.9 * _blob(x, y, 0.5 * SIZE[0], Y_C, sx=6.0)

    plug = lambda x, y: 0.15 + 0.85 * np.exp(-0.5 * ((y - Y_C) / 2.0) ** 2)  # noqa: E731
    box = next(b for b in BOXES if b.tag == "L45W15H15")
    changing = measure(_synthetic_run(tmp_path / "changing.h5", slug))
    assert changing.balanced and changing.plateau  # the energy says steady
    assert [h.pattern for h in changing.halves] == ["plug", "slug"]
    assert not changing.stationary
    assert steady_check(box, changing).verdict == PARTLY
    steady = measure(_synthetic_run(tmp_path / "steady.h5", plug))
    assert steady.stationary and steady.modes.pattern == "plug"
    assert steady_check(box, steady).verdict == REPRODUCED
    # a plateau is the halves' KE within 2σ or within 2 %: 1.2 % apart (2.3σ) is one; 6.7 %
    # (2.1σ, L18W30H30's halves) is not, and the row says by how much the KE still rises
    level = dataclasses.replace(steady, ke_halves=((1440.1, 5.2), (1422.3, 5.7)))
    assert level.plateau and steady_check(box, level).verdict == REPRODUCED
    rising = dataclasses.replace(steady, ke_halves=((6219.0, 198.0), (6637.0, 25.0)))
    row = steady_check(box, rising)
    assert not rising.plateau and row.verdict == PARTLY
    assert "the KE/N rises by 6.7 % from the first half" in row.reason
    # a slug at one snapshot window of the production (too short to move a half): the
    # structure has not settled, and the row names the window

    early = dataclasses.replace(steady, windows={11000.0: changing.halves[1]})
    assert early.window_changes == [11000.0] and not early.stationary
    check = steady_check(box, early)
    assert check.verdict == PARTLY and "11000 c/p: slug" in check.measured


def test_a_record_measures_as_its_run(tmp_path: Path) -> None:
    """A study record keeps the modes, the peak densities and the last frame instead of the
    frames: measuring it gives what measuring the full results file gives."""
    import h5py

    from demstudy.studies.malik2008.waves_measure import measure
    from demstudy.studies.records import write_record

    def slug(x, y):
        return 0.1 + 0.9 * _blob(x, y, 0.5 * SIZE[0], Y_C, sx=6.0)

    full = _synthetic_run(tmp_path / "full.h5", slug)
    record = write_record(full, tmp_path / "record.h5",
                          waves.derive(waves.BOXES[0].name, full))
    assert waves.derive("not-a-box", full) == {}
    with h5py.File(record, "r") as f:
        assert "frames" not in f
    a, b = measure(full), measure(record)
    assert [h.pattern for h in b.halves] == [h.pattern for h in a.halves] == ["plug", "slug"]
    assert b.modes.pattern == a.modes.pattern and b.stationary == a.stationary
    assert b.balance == a.balance and b.ke_halves == a.ke_halves and b.rate == a.rate
    assert b.peak == pytest.approx(a.peak) and b.peak_coarse == pytest.approx(a.peak_coarse)
    assert b.close_packed == a.close_packed and b.n == a.n
    np.testing.assert_allclose(b.snapshot.position, a.snapshot.position, rtol=1e-6)
    np.testing.assert_allclose(b.modes.results["family_power_xy"],
                               a.modes.results["family_power_xy"])
    for drift_a, drift_b in zip(a.drifts, b.drifts, strict=True):
        assert drift_b.sigmas == pytest.approx(drift_a.sigmas)


def test_the_class_at_the_thesis_snapshot_time_under_either_reading(tmp_path: Path) -> None:
    """Frames 500 c/p apart from 10500 c/p: a plug until 20000 c/p, then a slug. At the
    thesis's 14000 c/p read as ours the window holds a plug; read as N_pair/N (28000 of
    ours) a slug: the N = 50094 box's statement (slug at 14000) is reproduced under the
    second reading and says which. Windows without frames are absent; a record keeps them."""
    from demstudy.studies.base import NO_THESIS_VALUE, NOT_REPRODUCED, REPRODUCED
    from demstudy.studies.malik2008.waves_boxes import BOXES
    from demstudy.studies.malik2008.waves_measure import measure
    from demstudy.studies.malik2008.waves_report import class_check
    from demstudy.studies.records import write_record

    def slug(x, y):
        return 0.1 + 0.9 * _blob(x, y, 0.5 * SIZE[0], Y_C, sx=6.0)

    full = _synthetic_run(tmp_path / "late.h5", slug, rate=250.0)
    run = measure(full)
    assert run.windows[14000.0].pattern == "plug"
    assert run.windows[28000.0].pattern == "slug"
    assert 4000.0 not in run.windows and 8000.0 not in run.windows
    box = next(b for b in BOXES if b.fig == "5.6-5.10")
    check = class_check(box, run)
    assert check.verdict == REPRODUCED and "c/p = N_pair/N" in check.reason
    assert "14000 plug" in check.measured and "28000 slug" in check.measured
    record = write_record(full, tmp_path / "late-record.h5", waves.derive(box.name, full))
    kept = measure(record)
    assert {c: m.pattern for c, m in kept.windows.items()} == \
        {c: m.pattern for c, m in run.windows.items()}

    plug = lambda x, y: 0.15 + 0.85 * np.exp(-0.5 * ((y - Y_C) / 2.0) ** 2)  # noqa: E731
    never = class_check(box, measure(_synthetic_run(tmp_path / "plug.h5", plug, rate=250.0)))
    assert never.verdict == NOT_REPRODUCED and "under either reading" in never.reason
    # a box whose class the thesis does not state: the measurement, and nothing compared
    other = next(b for b in BOXES if b.fig == "5.13")
    unstated = class_check(other, run)
    assert unstated.verdict == NO_THESIS_VALUE and unstated.thesis == "not in the digest"
    assert unstated.measured.startswith(run.modes.pattern)


def test_a_large_tc_share_caps_the_box_verdicts_and_says_so(tmp_path: Path) -> None:
    """A box run whose pair collisions the TC model made elastic in a large share (20 %): an
    agreement becomes "partly", a mismatch stays "not reproduced", the share in the reason
    either way; 1 % changes nothing."""

    from demstudy.studies.base import NOT_REPRODUCED, PARTLY, REPRODUCED
    from demstudy.studies.malik2008.waves_boxes import BOXES
    from demstudy.studies.malik2008.waves_measure import measure
    from demstudy.studies.malik2008.waves_report import class_check, tc_caveat

    def slug(x, y):
        return 0.1 + 0.9 * _blob(x, y, 0.5 * SIZE[0], Y_C, sx=6.0)

    run = measure(_synthetic_run(tmp_path / "late.h5", slug, rate=250.0))
    box = next(b for b in BOXES if b.fig == "5.6-5.10")
    assert class_check(box, run).verdict == REPRODUCED
    low = tc_caveat(class_check(box, run), dataclasses.replace(run, tc_fraction=0.01))
    assert low.verdict == REPRODUCED and "TC" not in low.reason
    high = tc_caveat(class_check(box, run), dataclasses.replace(run, tc_fraction=0.2))
    assert high.verdict == PARTLY and "this box: 20.0 % (t_c = 1e-05 √(d/g))" in high.reason

    # the box's own TC twin agreed (same class and KE at a small share): no cap, said so;
    # another box's twin agreeing is mentioned, the cap stays
    from demstudy.studies.base import Check

    agreed = Check("TC model", "", "", "", REPRODUCED)
    lifted = tc_caveat(class_check(box, run), dataclasses.replace(run, tc_fraction=0.2),
                       agreed, ["L42W30H30"], "L70W50H50")
    assert lifted.verdict == REPRODUCED and "the share does not change the structure" in \
        lifted.reason and '(row "TC model, L70W50H50")' in lifted.reason
    other = tc_caveat(class_check(box, run), dataclasses.replace(run, tc_fraction=0.2),
                      None, ["L42W30H30"])
    assert other.verdict == PARTLY and "this box's share is not tested" in other.reason
    assert "TC twin of L42W30H30 at t_c = 1e-06 kept its class" in other.reason
    two = tc_caveat(class_check(box, run), dataclasses.replace(run, tc_fraction=0.2),
                    None, ["L42W30H30", "L90W30H30"])
    assert "TC twins of L42W30H30, L90W30H30 at t_c = 1e-06 kept their class" in two.reason
    alone = tc_caveat(class_check(box, run), dataclasses.replace(run, tc_fraction=0.2))
    assert alone.verdict == PARTLY and "twin" not in alone.reason
    # another box's twin that changed the class is named beside the ones that agreed
    both = tc_caveat(class_check(box, run), dataclasses.replace(run, tc_fraction=0.2),
                     None, ["L42W30H30"], "L70W50H50",
                     {"L150W50H10": NOT_REPRODUCED, "L90W30H30": PARTLY})
    assert ("kept its class; the TC twin of L150W50H10 changed the class; the TC twin of "
            "L90W30H30 kept the class but not the KE/N") in both.reason
    # a "partly" twin whose own share is large: said so
    shared = tc_caveat(class_check(box, run), dataclasses.replace(run, tc_fraction=0.2),
                       None, [], "L70W50H50", {"L90W30H30": PARTLY},
                       twin_shares={"L90W30H30": 0.056})
    assert ("the TC twin of L90W30H30 kept the class and the KE/N, but its own share "
            "(5.6 %) is above 5 %") in shared.reason
    only_bad = tc_caveat(class_check(box, run), dataclasses.replace(run, tc_fraction=0.2),
                         None, [], "L70W50H50", {"L150W50H10": NOT_REPRODUCED})
    assert "(the TC twin of L150W50H10 changed the class: rows" in only_bad.reason
    # without the tag, the own twin's row is named from its reference
    own = Check("TC model, L90W30H30 (demstudy; not in the thesis)", "", "", "", PARTLY)
    untagged = tc_caveat(class_check(box, run), dataclasses.replace(run, tc_fraction=0.2), own)
    assert '(row "TC model, L90W30H30")' in untagged.reason
    # a mismatch stays a mismatch: the TC share is named as one possible cause
    never = measure(_synthetic_run(tmp_path / "plug.h5", lambda x, y: 0.15 + 0.85 * np.exp(
        -0.5 * ((y - Y_C) / 2.0) ** 2), rate=250.0))
    missed = class_check(box, never)
    assert missed.verdict == NOT_REPRODUCED
    kept = tc_caveat(missed, dataclasses.replace(never, tc_fraction=0.2))
    assert kept.verdict == NOT_REPRODUCED and "a weaker test either way" in kept.reason
    # the box's own twin measured and disagreeing: said so, by its row's name, capped

    for verdict, said in ((NOT_REPRODUCED, "changes the class, so the structure depends"),
                          (PARTLY, "kept the class but not the KE/N, so an effect")):
        own = Check("TC model, L90W30H30 (demstudy; not in the thesis)", "", "", "", verdict)
        capped = tc_caveat(class_check(box, run), dataclasses.replace(run, tc_fraction=0.2),
                           own, ["L42W30H30"], "L90W30H30")
        assert capped.verdict == PARTLY and said in capped.reason
        assert '(row "TC model, L90W30H30")' in capped.reason
        assert "not tested" not in capped.reason


def test_the_tc_twin_check_compares_class_ke_and_share(tmp_path: Path) -> None:
    """The TC row: the same slug at both t_c with a small share at the smaller one is
    "reproduced"; a plug at the smaller t_c "not reproduced"; a KE apart or a large share at
    the smaller t_c "partly"; a missing twin "not run"."""

    from demstudy.studies.base import NOT_REPRODUCED, PARTLY, REPRODUCED
    from demstudy.studies.malik2008.waves_measure import measure
    from demstudy.studies.malik2008.waves_report import tc_dependence

    box = waves.twin_boxes()[1]

    def slug(x, y):
        return 0.1 + 0.9 * _blob(x, y, 0.5 * SIZE[0], Y_C, sx=6.0)

    plug = lambda x, y: 0.15 + 0.85 * np.exp(-0.5 * ((y - Y_C) / 2.0) ** 2)  # noqa: E731
    base = dataclasses.replace(measure(_synthetic_run(tmp_path / "a.h5", slug, rate=250.0)),
                               tc_fraction=0.06)
    twin = dataclasses.replace(base, tc_fraction=0.004)
    same = tc_dependence(box, base, twin)
    assert same.verdict == REPRODUCED and "share at 1e-06: 0.4 % < 5 %" in same.reason
    assert same.ref.startswith("TC model, L90W30H30") and "L90W30H30 (N = " in same.statement
    assert "TC share 6.0 %" in same.measured and "TC share 0.4 %" in same.measured
    assert "clock" not in same.reason  # the same collision rate: equal c/p is equal time
    faster = tc_dependence(box, base, dataclasses.replace(twin, rate=1.44 * base.rate))
    assert faster.verdict == REPRODUCED and "the collision clock runs ×1.44" in faster.reason
    assert "collide more often" in faster.reason
    slower = tc_dependence(box, base, dataclasses.replace(twin, rate=0.5 * base.rate))
    assert "runs ×0.50" in slower.reason and "collide less often" in slower.reason
    unknown_rate = tc_dependence(box, dataclasses.replace(base, rate=float("nan")), twin)
    assert "clock" not in unknown_rate.reason
    other = dataclasses.replace(measure(_synthetic_run(tmp_path / "b.h5", plug, rate=250.0)),
                                tc_fraction=0.004)
    differs = tc_dependence(box, base, other)
    assert differs.verdict == NOT_REPRODUCED and "the class differs" in differs.reason
    c = max(other.windows)  # one snapshot window a plug, the production still a slug
    window = dataclasses.replace(twin, windows={**twin.windows, c: other.windows[c]})
    once = tc_dependence(box, base, window)
    assert once.verdict == NOT_REPRODUCED and f"the class differs: at {c:.0f} c/p" in once.reason
    (m1, e1), (m2, e2) = base.ke_halves
    hotter = dataclasses.replace(twin, ke_halves=((m1, e1), (1.5 * m2, e2)))
    apart = tc_dependence(box, base, hotter)
    assert apart.verdict == PARTLY and "second half differs" in apart.reason
    # 8 % hotter, but 8σ: within 2σ + 10 % (the studies' TWIN_TOLERANCE), "reproduced", and
    # the reason gives both numbers
    err = 0.01 * m2 / np.sqrt(2)  # both halves' errors 1 % / √2: the difference is 4σ
    close = tc_dependence(box, dataclasses.replace(base, ke_halves=((m1, e1), (m2, err))),
                          dataclasses.replace(twin, ke_halves=((m1, e1), (1.08 * m2, err))))
    assert same.own and close.own
    assert close.verdict == REPRODUCED
    assert "KE/N halves differ by at most 8.0 % (8.0σ) (within 2σ + 10 %)" in close.reason
    beyond = tc_dependence(box, dataclasses.replace(base, ke_halves=((m1, e1), (m2, err))),
                           dataclasses.replace(twin, ke_halves=((m1, e1), (1.13 * m2, err))))
    assert beyond.verdict == PARTLY and "more than 2σ + 10 %" in beyond.reason
    # within the tolerance both, but one half resolved (35σ): the reason names it too
    sharp = ((m1, 0.001 * m1), (m2, 0.05 * m2))
    resolved = tc_dependence(box, dataclasses.replace(base, ke_halves=sharp),
                             dataclasses.replace(twin, ke_halves=(
                                 (1.05 * m1, 0.001 * m1), (1.12 * m2, 0.05 * m2))))
    assert resolved.verdict == REPRODUCED
    assert "at most 12.0 % (1.7σ); the other half 5.0 % (35.4σ, resolved)" in resolved.reason
    shared = tc_dependence(box, base, dataclasses.replace(twin, tc_fraction=0.08))
    assert shared.verdict == PARTLY and "≥ 5 %" in shared.reason
    unknown = tc_dependence(box, base, dataclasses.replace(twin, tc_fraction=float("nan")))
    assert unknown.verdict == PARTLY and "share at 1e-06: unknown" in unknown.reason
    wrong = tc_dependence(box, base, dataclasses.replace(twin, tc=1e-5))
    assert wrong.verdict == NOT_RUN and "ran at t_c = 1e-05, not 1e-06" in wrong.reason
    assert tc_dependence(box, dataclasses.replace(base, tc=1e-5),
                         dataclasses.replace(twin, tc=1e-6)).verdict == REPRODUCED
    missing = tc_dependence(box, base, None, "results file unreadable")
    assert missing.verdict == NOT_RUN and "unreadable" in missing.reason


def test_unbalanced_run_names_the_clock_that_dense_clumps_speed_up(tmp_path: Path) -> None:
    """A run still accelerating (input > dissipation) whose collision rate grows ×10 over the
    production (a slug forming): the KE against c/p rises ten times more slowly than in time,
    and the reason must say so with the measured rates; with a steady collision rate it must
    not blame the clock."""

    from demstudy.studies.base import NOT_REPRODUCED
    from demstudy.studies.malik2008.waves_boxes import BOXES
    from demstudy.studies.malik2008.waves_measure import measure
    from demstudy.studies.malik2008.waves_report import steady_check

    box = next(b for b in BOXES if b.tag == "L70W50H50")
    base = measure(_synthetic_run(tmp_path / "base.h5", lambda x, y: 0.15 + 0.0 * x))
    t = base.time
    prod = t - base.eq_end
    span = float(prod[-1])
    # c/p per unit time rises linearly from 100 to 1000 over the production
    cpp = np.where(prod > 0, 100.0 * prod + 450.0 * prod ** 2 / span, 100.0 * prod)
    ke = 1000.0 + 10.0 * t  # KE/N rises steadily in time
    running = dataclasses.replace(base, cpp=cpp, ke=ke, balance=(0.5, 0.02))
    clock = running.clock()
    assert 5.0 < clock.speed_up < 12.0
    # the KE's rise per unit c/p is the rise per unit time over the clock's late rate
    rel_t = clock.ke_per_10t / 10.0  # % per unit time
    assert math.isclose(clock.ke_per_kcpp, 1000.0 * rel_t / clock.end, rel_tol=0.05)
    check = steady_check(box, running)
    assert check.verdict == NOT_REPRODUCED
    assert "speed the clock up" in check.reason and f"×{clock.speed_up:.1f}" in check.reason
    assert "still accelerates" in check.reason

    steady_clock = dataclasses.replace(running, cpp=100.0 * t)
    check = steady_check(box, steady_clock)
    assert check.verdict == NOT_REPRODUCED and "clock" not in check.reason
    assert "runs longer in time" in check.reason

    slowing = dataclasses.replace(running, balance=(1.5, 0.02))
    assert "decelerates" in steady_check(box, slowing).reason


def test_peak_density_is_judged_box_by_box(tmp_path: Path) -> None:
    """The colour bars' ≈ 0.58: a box whose 2 d / 5 d peaks bracket 0.58 (± 2σ + 0.03)
    counts; one box in range makes the row "partly" (the thesis's cells are unknown), none
    "not reproduced", and a close-packed densest box is named only when it is out of range."""

    from demstudy.studies.base import NOT_REPRODUCED, PARTLY
    from demstudy.studies.malik2008.waves_measure import measure
    from demstudy.studies.malik2008.waves_report import peak_check

    plug = lambda x, y: 0.15 + 0.85 * np.exp(-0.5 * ((y - Y_C) / 2.0) ** 2)  # noqa: E731
    base = measure(_synthetic_run(tmp_path / "p.h5", plug))

    def box(fine: float, coarse: float, packed: float = 0.0):
        return dataclasses.replace(base, peak=(fine, 0.002), peak_coarse=(coarse, 0.002),
                                   close_packed=packed)

    runs = {"waves-phi0.15-L45W15H15-edmd": box(0.64, 0.58),
            "waves-phi0.15-L75W15H15-edmd": box(0.73, 0.68, packed=0.05)}
    row = peak_check(runs)
    assert row.verdict == PARTLY and "in 1 of 2 boxes" in row.reason
    assert "L45W15H15 0.6400 ± 0.0020 / 0.5800 ± 0.0020 (0.58 within)" in row.measured
    assert "the densest, L75W15H15, has 5.0 %" in row.reason
    none = peak_check({"waves-phi0.15-L9W15H15-edmd": box(0.39, 0.32)})
    assert none.verdict == NOT_REPRODUCED and "in every box" in none.reason
    assert peak_check({}).verdict == NOT_RUN


def test_the_sequence_of_classes_is_compared_with_the_thesis_order(tmp_path: Path) -> None:
    """N = 50094's plug → S-wave → slug: our windows' classes in time order (repeats merged,
    classes the thesis does not name skipped) must follow the thesis's order from some class
    on; a slug turning back into a plug is another order."""

    from demstudy.studies.malik2008.waves_measure import measure
    from demstudy.studies.malik2008.waves_report import sequence_text

    def slug(x, y):
        return 0.1 + 0.9 * _blob(x, y, 0.5 * SIZE[0], Y_C, sx=6.0)

    plug = lambda x, y: 0.15 + 0.85 * np.exp(-0.5 * ((y - Y_C) / 2.0) ** 2)  # noqa: E731
    p = measure(_synthetic_run(tmp_path / "p.h5", plug)).modes
    run = measure(_synthetic_run(tmp_path / "s.h5", slug))
    s = run.modes
    assert (p.pattern, s.pattern) == ("plug", "slug")
    thesis = ("plug", "s-wave", "slug")
    forward = dataclasses.replace(run, windows={4000.0: p, 8000.0: p, 11000.0: s})
    assert "windows plug → slug: the same order (s-wave not caught at the windows)" in \
        sequence_text(forward, thesis)
    late = dataclasses.replace(run, windows={11000.0: s, 14000.0: s})
    assert ("the same order from the slug on (no window before 11000 c/p: whether the plug "
            "and s-wave came first is not measured)") in sequence_text(late, thesis)
    early = dataclasses.replace(run, windows={4000.0: p, 8000.0: p})
    assert "the same order, but it stops at the plug" in sequence_text(early, thesis)
    back = dataclasses.replace(run, windows={4000.0: s, 8000.0: p})
    assert sequence_text(back, thesis).endswith("another order")
    assert sequence_text(forward, ()) == ""


def test_when_both_readings_show_the_class_the_earlier_snapshots_tell_them_apart() -> None:
    """N = 50094's slug "forms at ≈ 14000 c/p": a run with S-waves until 10000 of our c/p and
    a slug from 11000 shows the slug at 14000 under both readings of the thesis's clock, but
    its first slug is at the thesis's 11000 read as 2 N_pair/N and at 8000 read as N_pair/N
    (our 16000): the first reading fits better, and the text says so."""
    import types

    from demstudy.studies.malik2008.waves_report import first_seen_text, method_text

    def at(c):
        return types.SimpleNamespace(cls="s-wave" if c < 11000 else "slug")

    run = types.SimpleNamespace(windows={c: at(c) for c in waves_measure_windows()})
    text = first_seen_text(run, "slug", 14000.0)
    assert "read as 2 N_pair/N the first slug is at the thesis's 11000 c/p" in text
    assert "read as N_pair/N the first slug is at the thesis's 8000 c/p" in text
    assert "the 2 N_pair/N reading fits better" in text
    never = types.SimpleNamespace(windows={c: types.SimpleNamespace(cls="plug")
                                           for c in waves_measure_windows()})
    assert first_seen_text(never, "slug", 14000.0) == ""

    # the method's numbers come from the runs: 7000 √(d/g) at 200-1000 c/p per √(d/g)
    from demstudy.studies.malik2008.waves_boxes import BOXES

    wide = [b for b in BOXES if b.width >= 30][:2]
    measured = {b.name: types.SimpleNamespace(rate=r, tc_fraction=f)
                for b, r, f in zip(wide, (200.0, 1000.0), (0.03, 0.12), strict=True)}
    method = method_text(measured)
    assert "1.4e+06-7.0e+06 c/p" in method and "×47-233 the cost" in method
    assert "3.0-12.0 % of the W = 30/50 boxes' pair collisions" in " ".join(method.split())
    assert "{" not in method


def waves_measure_windows() -> list[float]:
    from demstudy.studies.malik2008.waves_measure import SNAPSHOTS

    return sorted({*SNAPSHOTS, *(2.0 * t for t in SNAPSHOTS)})
