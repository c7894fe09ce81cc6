"""Inputs refused in quadimpact's own one line, naming the field, the rule and the values
(issue 60 item 6): a task named twice, a non-finite ``--param``, a study folder's other
options (the option and both values in full), ``estimators --n`` beyond its limit."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from quadimpact.errors import InputError
from quadimpact.studies.benchmark.suite import parse_tasks
from quadimpact.studies.study_folder import StudyFolder

from helpers import cli_here


def one_error_line(capsys, *args: str) -> str:
    """The one ``quadimpact: error:`` line of ``quadimpact ARGS`` (exit status 2)."""
    code, err = cli_here(capsys, *args)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, (code, err)
    assert lines[0].startswith("quadimpact: error: "), err
    return lines[0].removeprefix("quadimpact: error: ")


def test_a_task_named_twice_is_refused() -> None:
    with pytest.raises(InputError, match=r"^--tasks: each task at most once; 'wall' named more"):
        parse_tasks("wall,wall")
    with pytest.raises(InputError, match=r"'pole', 'wall' named more than once"):
        parse_tasks("wall, pole,wall,pole")
    assert parse_tasks("pole,wall") == ("wall", "pole")


def test_the_benchmark_refuses_a_task_named_twice(capsys, tmp_path: Path) -> None:
    line = one_error_line(capsys, "benchmark", "--quick", "--tasks", "wall,wall",
                          "--out", str(tmp_path / "b"))  # fmt: skip
    assert line.startswith("--tasks: each task at most once"), line
    assert not (tmp_path / "b").exists()


@pytest.mark.parametrize(
    ("value", "rule"),
    [("nan", "must be a finite number"), ("inf", "must be a finite number"),
     ("-1e999", "must be a finite number"), ("25,nan", "must be finite numbers")],
)  # fmt: skip
def test_a_non_finite_param_says_a_finite_number(capsys, tmp_path, value, rule) -> None:
    line = one_error_line(capsys, "run", "--controller", "recovery", "--param",
                          f"k_att_1_s={value}", "--out", str(tmp_path / "r"))  # fmt: skip
    assert line == f"--param: k_att_1_s: {rule} (got {value!r})"
    line = one_error_line(capsys, "run", "--option", f"contact_gate_m={value}",
                          "--out", str(tmp_path / "r"))  # fmt: skip
    assert line == f"--option: contact_gate_m: {rule} (got {value!r})"


def test_a_refused_folder_names_the_option_and_both_values_in_full(tmp_path: Path) -> None:
    policy = "policies/" + "a-very-long-folder-name/" * 4 + "policy.npz"  # > 60 characters
    flags = {"n": "--n", "policy": "--policy", "policy_sha256": "--policy"}
    held = {"n": 10, "policy": policy, "policy_sha256": "a" * 64}
    StudyFolder(tmp_path, "recovery", held, flags=flags).claim()
    asked = {**held, "policy": policy.replace("policy.npz", "other.npz"), "policy_sha256": "b" * 64}
    with pytest.raises(InputError) as refused:
        StudyFolder(tmp_path, "recovery", asked, flags=flags).check()
    message = str(refused.value)
    # one --policy (the path, not also its digest), both paths whole
    assert f"(--policy {policy!r} there, {asked['policy']!r} asked);" in message, message
    assert "..." not in message


def test_a_refused_estimator_folder_names_the_nested_option(tmp_path: Path) -> None:
    from quadimpact.studies.estimators.estimator_study import EstimatorStudy, study_folder

    study = EstimatorStudy(scenario="authors-2016", n=2)
    study_folder(study, tmp_path).claim()
    other = dataclasses.replace(
        study, approach=dataclasses.replace(study.approach, hover_s=6.0), loop="in"
    )
    with pytest.raises(InputError) as refused:
        study_folder(other, tmp_path).check()
    message = str(refused.value)
    assert "(--hover 4.0 there, 6.0 asked; --loop 'default' there, 'in' asked)" in message


@pytest.mark.parametrize("n", ["1e12", "100001", "0", "2.5", "ten"])
def test_estimators_n_beyond_its_limit_is_quadimpacts_own_message(capsys, tmp_path, n) -> None:
    line = one_error_line(capsys, "estimators", "--n", n, "--out", str(tmp_path / "e"))
    assert line == f"--n: must be a whole number of trials from 1 to 100,000 (got {n!r})"


def test_estimators_n_takes_a_whole_number_written_as_one() -> None:
    from quadimpact.cli.options import Count

    assert Count(1, 100_000, "trials").convert("1e3", None, None) == 1000
