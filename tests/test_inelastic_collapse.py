"""Inelastic collapse with the TC model switched off (``--tc 0``): the event-driven engine's
stall watch names the cause and the remedy, and keeps the zero-gap-loop message where that
is the cause. Dimensionless particle units: d = 1, m = 1, g = 1 when gravity acts (the HCS
scene: the initial temperature T0 = 1 sets the time unit)."""

from __future__ import annotations

import pytest
from test_edmd_walls import caged_disc

from demstudy.cli import main
from demstudy.engines.edmd import core
from demstudy.errors import EngineError
from demstudy.io.results import read_results

# a dense, strongly inelastic 2D cooling gas: with t_c = 0 it collapses at t ≈ 0.44 (357 discs)
DENSE_HCS = ["run", "cooling/hcs-3d", "--engine", "edmd", "--set", "dimension=2",
             "--set", "box.size=[20,20]", "--set", "particles.solid_fraction=0.7",
             "--set", "contact.restitution=0.3", "--set", "run.production=20", "-q"]


@pytest.fixture
def small_window(monkeypatch):
    """A stall window of 2·10⁵ events instead of 10⁷, so the collapse is caught in ~0.2 s
    (the run is forked from this process, which passes the patch on)."""
    monkeypatch.setattr(core, "STALL_CHUNK", 200_000)
    monkeypatch.setattr(core, "STALL_CHUNK_PER_PARTICLE", 100)


def test_collapse_with_tc_off_names_the_cause_and_the_remedy(tmp_path, capsys, small_window):
    """--tc 0 on a dense HCS at e = 0.3: exit 1, one message naming inelastic collapse and
    the default t_c, no traceback, no results file. The remedy works: the default t_c runs the same
    scene to its end, with the TC model having made collisions elastic."""
    out = tmp_path / "collapse.h5"
    assert main([*DENSE_HCS, "--tc", "0", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "inelastic collapse" in err and "Rerun without --tc (the default t_c, 1e-5 " in err
    assert "crystalline row" not in err and "Traceback" not in err
    assert "0 wall collisions" in err  # the diagnosis: pair collisions, no time passing
    assert not out.exists()
    assert main([*DENSE_HCS, "--out", str(out)]) == 0
    results = read_results(out)
    assert results.timeseries["time"][-1] == pytest.approx(20.0)
    assert results.attrs["elastic_tc_collisions"] > 0


def test_caged_disc_keeps_the_zero_gap_message(small_window):
    """A disc caged at zero gaps between two bumps (e = 0.5, t_c = 0) loops at t = 0 for
    ever (its speed stops at the smallest double): no t_c would cure that, so the message is
    the cage's, not collapse's; the elastic cage likewise."""
    for e in (0.5, 1.0):
        with pytest.raises(EngineError, match=r"stalled at t = 0\b.*zero gaps") as info:
            core.advance_watched(caged_disc(e), 1.0, tc=0.0, dissipative=e < 1, bumps=True,
                                 max_events=2_000_000)
        assert "collapse" not in str(info.value)
