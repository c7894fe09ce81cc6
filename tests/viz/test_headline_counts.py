"""The viewer's headline and ``quadimpact run``'s summary count a run's contact episodes
the same way (issue 60 item 5: the headline said "0 episode(s)" where the summary said
"episodes 1" for the same run)."""

from __future__ import annotations

import re
from pathlib import Path

from quadimpact import WallApproach, simulate
from quadimpact.cli.run_command import format_summary
from quadimpact.viz.scene import Scene
from quadimpact.viz.viewer import viewer_data


def test_the_headline_and_the_run_summary_give_the_same_episode_count() -> None:
    result = simulate(WallApproach(heading_deg=20.0, final_time_s=0.8))
    n = len(result.episodes)  # the episodes themselves: one bumper touched the wall once
    assert n == 1 and result.summary["n_subsequent_impacts"] == 0
    headline = viewer_data(Scene.from_result(result))["subtitle"]
    said = re.findall(r"(\d+) (?:contact )?episode", headline)
    cli = re.search(r"^episodes +(\d+)$", format_summary(result.summary, Path("out")), re.M)
    assert said == [str(n)] and cli is not None and cli.group(1) == str(n), (headline, cli)
    assert "1 contact episode in all" in headline
