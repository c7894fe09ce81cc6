"""Every kind of figure is laid out so that nothing is cut or covered (issue 46 item 7).

Each figure the package draws is made from small inputs (short runs, a few
trials, a tiny pole grid), with its own titles and with a long one, and drawn;
then every title (the figure's and each panel's), axis label and legend must
lie inside the canvas, the figure's title over no panel, and no legend over
the highest point of a curve (the issue's case: a single-panel sweep over
inclination at 45 deg of heading, whose long title was cut on both sides and
whose legend sat on a curve's peak).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure
from matplotlib.text import Text
from matplotlib.transforms import Bbox

TOLERANCE_PX = 1.0
#: The figures are checked drawn at this resolution (what is inside at one is inside at
#: any: text and margins scale with it), to draw fewer pixels.
DRAW_DPI = 40


def _texts(fig: Figure) -> Iterator[tuple[str, Any]]:
    """(what, artist) of every title, axis label and legend of a figure."""
    if fig._suptitle is not None and fig._suptitle.get_text():
        yield "suptitle", fig._suptitle
    for i, ax in enumerate(fig.axes):
        if not ax.get_visible() or not ax.axison and not ax.get_title():
            continue
        for where, title in (("title", ax.title), ("left title", ax._left_title),
                             ("right title", ax._right_title)):  # fmt: skip
            if title.get_text():
                yield f"axes {i} {where}", title
        for label in (ax.xaxis.label, ax.yaxis.label):
            if label.get_text() and label.get_visible():
                yield f"axes {i} label {label.get_text()!r}", label
        if ax.get_legend() is not None:
            yield f"axes {i} legend", ax.get_legend()
    for k, legend in enumerate(fig.legends):
        yield f"figure legend {k}", legend


def outside_the_canvas(fig: Figure) -> list[str]:
    """What of a drawn figure's titles, labels and legends sticks out of its canvas."""
    fig.set_dpi(DRAW_DPI)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    canvas = fig.bbox
    out = []
    for what, artist in _texts(fig):
        box = artist.get_window_extent(renderer)
        if (
            box.x0 < canvas.x0 - TOLERANCE_PX
            or box.y0 < canvas.y0 - TOLERANCE_PX
            or box.x1 > canvas.x1 + TOLERANCE_PX
            or box.y1 > canvas.y1 + TOLERANCE_PX
        ):
            text = artist.get_text() if isinstance(artist, Text) else ""
            out.append(f"{what} {text[:40]!r}: {box.bounds} outside {canvas.bounds}")
    title = fig._suptitle
    if title is not None and title.get_text():  # nor drawn over a panel (its title included)
        box = title.get_window_extent(renderer)
        for i, ax in enumerate(fig.axes):
            if ax.get_visible() and box.overlaps(ax.get_tightbbox(renderer)):
                out.append(f"suptitle over axes {i}: {box.bounds}")
    return out


def covered_peaks(fig: Figure) -> list[str]:
    """The curves whose highest point lies under a legend (an axes' own, or the figure's),
    in a figure :func:`outside_the_canvas` drew."""
    renderer = fig.canvas.get_renderer()
    covered = []
    for i, ax in enumerate(fig.axes):
        legends = [ax.get_legend(), *fig.legends]
        boxes: list[Bbox] = [g.get_window_extent(renderer) for g in legends if g is not None]
        for line in ax.get_lines():  # the data's, not marks across the axes (axvline...)
            y = np.asarray(line.get_ydata(), dtype=float)
            if line.get_transform() != ax.transData or y.size == 0 or not np.isfinite(y).any():
                continue
            k = int(np.nanargmax(y))
            px, py = ax.transData.transform((float(np.asarray(line.get_xdata())[k]), y[k]))
            if any(box.contains(px, py) for box in boxes):
                covered.append(f"axes {i}: the peak of {line.get_label()!r} under a legend")
    return covered


# ------------------------------------------------------------------ the inputs
@pytest.fixture(scope="module")
def runs() -> dict[str, Any]:
    """A wall approach, an impact trial with recovery and the EKF, and a sweep table."""
    from quadimpact import ImpactTrial, WallApproach, simulate

    wall = simulate(WallApproach(heading_deg=45, inclination_deg=15, speed_m_s=0.75,
                                 final_time_s=1.0))  # fmt: skip
    trial = simulate(ImpactTrial(vehicle="navi", controller="recovery", estimator="ekf",
                                 pitch_deg=-20, speed_m_s=1.5, final_time_s=1.0))  # fmt: skip
    return {"wall": wall, "trial": trial}


@pytest.fixture(scope="module")
def sweep_45(tmp_path_factory: pytest.TempPathFactory) -> pd.DataFrame:
    """The issue's sweep: heading 45 deg, inclination -20..20 deg, three speeds."""
    from quadimpact.sweep import SweepSpec, run_sweep

    spec = SweepSpec(grid={"heading_deg": [45.0], "inclination_deg": list(range(-20, 21, 2)),
                           "speed_m_s": [0.5, 0.75, 1.0]})  # fmt: skip
    return run_sweep(spec, tmp_path_factory.mktemp("sweep45"), workers=1)


@pytest.fixture(scope="module")
def trials() -> pd.DataFrame:
    """A few recovery trials with the study's derived columns."""
    from quadimpact.studies.recovery.recovery_study import RecoveryStudy, run_trials

    return run_trials(RecoveryStudy(n=12, seed=2), _tmp("trials"), workers=1)[1]


@pytest.fixture(scope="module")
def pole_table() -> pd.DataFrame:
    from quadimpact.studies.pole.pole_study import PoleStudy, run_pole_study

    study = PoleStudy(pitch_step_deg=15.0, offset_step_m=0.175)
    return run_pole_study(study, _tmp("pole"), workers=1).table


_TMP: dict[str, Any] = {}


def _tmp(name: str) -> Any:
    return _TMP["factory"].mktemp(name)


@pytest.fixture(scope="module", autouse=True)
def _factory(tmp_path_factory: pytest.TempPathFactory) -> None:
    _TMP["factory"] = tmp_path_factory


#: A title as long as a user's may be (a scenario described in full, a study's options).
LONG = ("Crash 7: matched conditions (heading 180 deg as flown, rear first, climbing and "
        "drifting into the wall), paper-replica with the crash-run switches, against its "
        "flight log and the default model")  # fmt: skip


def _figures(
    runs: dict[str, Any],
    sweep_45: pd.DataFrame,
    trials: pd.DataFrame,
    pole_table: pd.DataFrame,
    title: str | None,
) -> dict[str, Callable[[], Figure]]:
    """Every kind of figure, made when called; ``title``: theirs (None: their defaults)."""
    from quadimpact.experiments.compare import compare
    from quadimpact.results import estimate_figures, figures
    from quadimpact.results.sweep_figures import type_map_figure
    from quadimpact.studies.paper import paper_study
    from quadimpact.studies.pole import pole_figures
    from quadimpact.studies.recovery import recovery_analysis as analysis
    from quadimpact.studies.recovery import recovery_figures
    from quadimpact.sweep.plots import fixed_parameters, plot_metric
    from quadimpact.sweep.spec import SweepSpec
    from quadimpact.viz.animation import DEFAULT_ANIMATION_CAMERA, AnimationFigure
    from quadimpact.viz.scene import Scene
    from quadimpact.viz.snapshots import PAPER_FIGURE_TIMES, make_snapshots

    from synthetic_log import synthetic_log

    wall, trial = runs["wall"], runs["trial"]
    spec = SweepSpec(grid={"heading_deg": [45.0], "inclination_deg": [0.0, 5.0],
                           "speed_m_s": [0.5, 1.0]})  # fmt: skip
    swept = title or f"Initial deflection δ_init; {fixed_parameters(spec)}"
    numbers = analysis.summarise(trials)
    comparison = compare(wall, synthetic_log(wall, offsets={"roll_deg": 2.0}))
    run_title = title or wall.plot_title()
    trial_title = title or trial.plot_title()
    return {
        "fig5": lambda: figures.make_fig5(wall.timeseries, title=run_title),
        "fig6": lambda: figures.make_fig6(
            wall.timeseries, wall.references, wall_x_m=wall.wall_x_m(), title=run_title
        ),
        "imu": lambda: figures.make_imu(
            trial.imu, trial.timeseries, trial.summary, title=trial_title
        ),  # fmt: skip
        "estimate": lambda: estimate_figures.make_estimate(
            trial.imu, trial.timeseries, trial.summary, title=trial_title
        ),
        "sweep metric": lambda: plot_metric(
            sweep_45, "inclination_deg", by="speed_m_s", title=swept
        ),  # fmt: skip
        "sweep metric, panels": lambda: plot_metric(
            sweep_45.assign(heading_deg=np.where(sweep_45.index % 2, 0.0, 45.0)),
            "inclination_deg",
            by="speed_m_s",
            facet="heading_deg",
            title=swept,
        ),
        "sweep type map": lambda: type_map_figure(
            sweep_45, "inclination_deg", "speed_m_s", title=swept
        ),  # fmt: skip
        "figure 4": lambda: paper_study.fig4_figure(sweep_45.assign(model="default"), "default"),
        "pole maps": lambda: pole_figures.maps_figure(pole_table, title=title),
        "pole success": lambda: pole_figures.success_by_pitch_figure(pole_table, title=title),
        "success map": lambda: recovery_figures.success_map_figure(trials, title=title),
        "success by bin": lambda: recovery_figures.success_by_bin_figure(numbers, title=title),
        "compare by bin": lambda: recovery_figures.compare_by_bin_figure(
            {"default": numbers, "recovery-replica": numbers}, title=title
        ),
        "distributions": lambda: recovery_figures.distributions_figure(trials, title=title),
        "example trial": lambda: recovery_figures.example_figure(trial, title=title),
        "log comparison": lambda: comparison.figure(title=title),
        "snapshots": lambda: make_snapshots(
            Scene.from_result(wall), PAPER_FIGURE_TIMES[8], title=title
        ),  # fmt: skip
        "animation": lambda: (
            AnimationFigure(Scene.from_result(wall), DEFAULT_ANIMATION_CAMERA, 1280, 720).fig
        ),
    }


@pytest.mark.parametrize("title", [None, LONG], ids=["their titles", "long titles"])
def test_every_figure_keeps_its_titles_and_legends_inside_and_its_peaks_uncovered(
    runs, sweep_45, trials, pole_table, title
) -> None:
    bad = {}
    for kind, make in _figures(runs, sweep_45, trials, pole_table, title).items():
        fig = make()
        problems = outside_the_canvas(fig) + covered_peaks(fig)
        if problems:
            bad[kind] = problems
    assert not bad, "\n".join(f"{kind}: {'; '.join(what)}" for kind, what in bad.items())


def test_the_sweep_plot_of_the_issue_keeps_its_legend_off_the_peaks(sweep_45) -> None:
    from quadimpact.sweep.plots import plot_metric

    fig = plot_metric(sweep_45, "inclination_deg", by="speed_m_s",
                      title="Initial deflection δ_init; model default, controller paper, "
                      "vehicle spiri, heading ψ = 45 deg, ground crash")  # fmt: skip
    assert outside_the_canvas(fig) == [] and covered_peaks(fig) == []
