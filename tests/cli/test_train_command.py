"""``quadimpact train`` end to end: a small problem trains, stops on Ctrl-C with its state
saved, resumes from it with the same command, and its policy flies in the benchmark."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from helpers import sigint_as_on_a_terminal

pytest.importorskip("cma")

SRC = str(Path(__file__).resolve().parents[2] / "src")
SMALL = ["--tasks", "wall", "--sensors", "ideal", "--popsize", "3", "--batch", "2",
         "--check", "2", "--check-every", "1", "--hidden", "2", "--minutes", "0.5"]  # fmt: skip


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "quadimpact.cli", *args]


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": SRC + os.pathsep + os.environ.get("PYTHONPATH", "")}


def _generations(out: Path) -> int:
    curve = out / "curve.csv"
    return max(len(curve.read_text().splitlines()) - 2, 0) if curve.is_file() else 0


@pytest.mark.slow
def test_train_stops_on_ctrl_c_resumes_and_its_policy_flies_in_the_benchmark(tmp_path):
    out = tmp_path / "train"
    proc = subprocess.Popen(_cli("train", *SMALL, "--out", str(out)), env=_env(),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=sigint_as_on_a_terminal)  # fmt: skip
    deadline = time.monotonic() + 600
    while _generations(out) < 1 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.2)
    assert proc.poll() is None, proc.communicate()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 130, err
    assert "training interrupted at generation" in err and "resume" in err
    saved = json.loads((out / "train.json").read_text())
    assert saved["finished"] is False and saved["generations"] >= 1
    assert (out / "policy.npz").is_file() and (out / "state.pkl").is_file()

    res = subprocess.run(_cli("train", *SMALL, "--out", str(out)), env=_env(),
                         capture_output=True, text=True, timeout=900)  # fmt: skip
    assert res.returncode == 0, res.stderr
    assert f"(resumed at generation {saved['generations']})" in res.stdout
    done = json.loads((out / "train.json").read_text())
    assert done["finished"] is True and done["generations"] > saved["generations"]
    assert done["minutes"] >= 0.5 and len(done["sessions"]) == 2
    assert {"policy.npz", "curve.csv", "curve.png", "train.json"} <= {p.name for p in out.iterdir()}

    policy = out / "policy.npz"
    bench = subprocess.run(
        _cli("benchmark", "--quick", "--policy", str(policy), "--tasks", "pole", "--sensors",
             "ideal", "--no-references", "--no-cache", "--no-progress", "--out",
             str(tmp_path / "bench")),
        env=_env(), capture_output=True, text=True, timeout=900,
    )  # fmt: skip
    assert bench.returncode == 0, bench.stderr
    report = (tmp_path / "bench" / "report.md").read_text()
    assert str(policy) in report and "pole" in report


def test_train_refuses_bad_options_in_one_line(tmp_path):
    res = subprocess.run(_cli("train", "--seed", "0", "--out", str(tmp_path / "x")),
                         env=_env(), capture_output=True, text=True, timeout=300)  # fmt: skip
    assert res.returncode == 2
    assert res.stderr.strip().splitlines() == [
        "quadimpact: error: --seed: 0 is the benchmark's own seed; training trials must come "
        "from another (any integer >= 1)"
    ]
    res = subprocess.run(_cli("train", "--tasks", "wall,roof", "--out", str(tmp_path / "x")),
                         env=_env(), capture_output=True, text=True, timeout=300)  # fmt: skip
    assert res.returncode == 2 and "--tasks: unknown task 'roof'" in res.stderr
    assert not (tmp_path / "x").exists()


def test_run_flies_a_policy_file_given_by_its_flag(tmp_path):
    """``quadimpact run --policy FILE`` is ``--param policy=FILE``: the run records the file,
    and a strong policy of every stage flies another trajectory than the law."""
    import numpy as np

    from quadimpact.inputs.policy_file import initial_policy, save_policy

    p = initial_policy(8, 0.3, 4.0, seed=3, last_stage=5)
    p = p.with_vector(np.random.default_rng(3).normal(0, 1.0, p.vector().size))
    path = save_policy(p, tmp_path / "my policy.npz")
    trial = tmp_path / "trial.toml"
    trial.write_text('kind = "impact-trial"\nvehicle = "navi"\ncontroller = "recovery"\n'
                     'pitch_deg = -20.0\nspeed_m_s = 1.5\nfinal_time_s = 1.0\n')  # fmt: skip
    heights = []
    for extra, name in (([], "law"), (["--policy", str(path)], "policy")):
        res = subprocess.run(_cli("run", str(trial), *extra, "--out", str(tmp_path / name)),
                             env=_env(), capture_output=True, text=True, timeout=600)  # fmt: skip
        assert res.returncode == 0, res.stderr
        summary = json.loads((tmp_path / name / "summary.json").read_text())
        heights.append(summary["final_altitude_m"])
    scenario = json.loads((tmp_path / "policy" / "scenario.json").read_text())
    assert scenario["scenario"]["controller_params"]["policy"] == str(path)
    assert heights[0] != heights[1]
