"""tools/geometry_acceptance.py --seeds: the table over draws (medians, ranges, criteria on the
median draw and per draw), on hand-made per-seed tables; and its argument errors."""
import importlib.util
import os
import subprocess
import sys

import pytest

HERE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(HERE, "tools", "geometry_acceptance.py")


def load():
    spec = importlib.util.spec_from_file_location("geometry_acceptance", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


ga = load()


def row(sequence, depth, sim3, tracked=100, frames=100, vs_none=None, met=True, **extra):
    r = dict(sequence=sequence, depth=depth, frames=frames, tracked=tracked, sim3=sim3,
             se3=sim3 * 1.5, scale=1.0, tracked_from_init=1.0,
             criteria=ga.CRITERIA.get((ga.base(sequence), depth), {}), met=met)
    if vs_none is not None:
        r["vs_none"] = vs_none
        r["vs_none_all"] = vs_none
    r.update(extra)
    return r


def test_medians_ranges_and_the_median_draws_verdict(capsys):
    # KITTI's network row: sim3 at most 0.7 m and at most 1.1x none, every frame.
    tables = {
        42: [row("kitti", "none", 0.36), row("kitti", "network", 0.39, vs_none=1.07)],
        1: [row("kitti", "none", 0.35), row("kitti", "network", 0.37, vs_none=1.15, met=False)],
        2: [row("kitti", "none", 0.36), row("kitti", "network", 0.36, vs_none=0.97)],
    }
    out, ok = ga.draws_table(tables)
    network = [r for r in out if r["depth"] == "network"][0]
    assert network["draws"] == 3
    assert network["sim3"] == pytest.approx(0.37)
    assert network["sim3_range"] == pytest.approx([0.36, 0.39])
    assert network["vs_none"] == pytest.approx(1.07)
    assert network["met_draws"] == 2
    assert network["met"] and ok
    printed = capsys.readouterr().out
    assert "| kitti | network | 100/100 | 0.3700 (0.3600-0.3900) |" in printed
    assert "| 1.07 (0.97-1.15) | 2 of 3 | yes |" in printed


def test_a_median_ratio_over_the_bound_fails_even_if_one_draw_met():
    tables = {
        42: [row("kitti_late", "none", 0.12), row("kitti_late", "network", 0.15, vs_none=1.20)],
        1: [row("kitti_late", "none", 0.14), row("kitti_late", "network", 0.15, vs_none=1.07)],
        2: [row("kitti_late", "none", 0.13), row("kitti_late", "network", 0.16, vs_none=1.18)],
    }
    out, ok = ga.draws_table(tables)
    network = [r for r in out if r["depth"] == "network"][0]
    assert network["vs_none"] == pytest.approx(1.18)
    assert not network["met"] and network["failed"] == ["vs none"]
    assert not ok


def test_every_frame_holds_on_the_median_draw_only_if_most_draws_tracked_every_frame():
    def tables(tracked):
        return {s: [row("bonn", "none", 0.016),
                    row("bonn", "network", 0.014, tracked=t, frames=464, vs_none=0.8)]
                for s, t in zip((42, 1, 2), tracked)}
    most, _ = ga.draws_table(tables((464, 464, 460)))
    assert [r for r in most if r["depth"] == "network"][0]["met"]
    few, ok = ga.draws_table(tables((464, 460, 459)))
    network = [r for r in few if r["depth"] == "network"][0]
    assert network["failed"] == ["every frame"] and not ok


def test_a_geometric_run_that_never_initialised_compares_nothing():
    tables = {
        42: [row("bonn_late", "none", 0.033), row("bonn_late", "network", 0.019, vs_none=0.45)],
        1: [dict(row("bonn_late", "none", 0.0), sim3=None, never_initialised=True),
            row("bonn_late", "network", 0.019)],
    }
    out, ok = ga.draws_table(tables)
    network = [r for r in out if r["depth"] == "network"][0]
    assert network["vs_none"] == pytest.approx(0.45)  # from the one draw that had a none run
    none = [r for r in out if r["depth"] == "none"][0]
    assert none["sim3"] == pytest.approx(0.033) and not none["never_initialised"]
    assert ok


def test_no_draw_with_a_geometric_run_leaves_the_ratio_out():
    never = dict(row("bonn_late", "none", 0.0, tracked=0, frames=0), sim3=None, se3=None,
                 scale=None, tracked_from_init=None, never_initialised=True)
    tables = {s: [dict(never), row("bonn_late", "network", 0.019, tracked=232, frames=232)]
              for s in (42, 1)}
    out, ok = ga.draws_table(tables)
    network = [r for r in out if r["depth"] == "network"][0]
    assert network["vs_none"] is None and network["met"] and ok
    none = [r for r in out if r["depth"] == "none"][0]
    assert none["sim3"] is None and none["never_initialised"]


@pytest.mark.parametrize("args, message", [
    (["--seed", "1", "--seeds", "1,2"], "--seed and --seeds exclude each other"),
    (["--seeds", "1,x"], "--seeds: a comma-separated list of integers"),
    (["--seeds", "2,2"], "--seeds: at least one seed, each once"),
])
def test_bad_seed_lists_are_one_line_errors(tmp_path, args, message):
    r = subprocess.run([sys.executable, SCRIPT, "--out", str(tmp_path / "out")] + args,
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert message in r.stderr
    assert not (tmp_path / "out").exists()  # nothing written
