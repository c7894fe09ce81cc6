"""Stamps (``viz/stamps.py``): a text's pixels kept once and pasted where it moves."""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from quadimpact.viz.stamps import Stamp, TextStamp, text_anchor


def _canvas() -> tuple[FigureCanvasAgg, Figure]:
    fig = Figure(figsize=(2.0, 1.0), dpi=100)
    return FigureCanvasAgg(fig), fig


def _drawn(x: float, y: float) -> np.ndarray:
    """The text drawn by matplotlib at display position (x, y) on a white canvas."""
    canvas, fig = _canvas()
    fig.text(x, y, "4z", transform=None, fontsize=9, color="#d95f02", ha="center", va="center")
    canvas.draw()
    return np.asarray(canvas.buffer_rgba()).copy()


def test_a_pasted_text_is_the_text_drawn_there_and_moves_by_whole_pixels() -> None:
    canvas, fig = _canvas()
    text = fig.text(60.3, 40.6, "4z", transform=None, fontsize=9, color="#d95f02",
                    ha="center", va="center")  # fmt: skip
    canvas.draw()
    stamp = Stamp([text], text_anchor(text))
    stamp.capture(canvas)
    assert stamp.rgba is not None and 5 < stamp.rgba.shape[1] < 40
    for x, y in ((60.3, 40.6), (60.3 + 71, 40.6 - 17), (60.3 - 58, 40.6)):  # the last cut at 0
        text.set_position((x, y))
        pixels = np.full((100, 200, 4), 255, dtype=np.uint8)
        stamp.paste(pixels)
        expected = _drawn(x, y)
        assert (expected[:, :, :3] < 250).any()  # the text is there
        assert np.abs(pixels.astype(int) - expected.astype(int)).max() <= 1


def test_a_hidden_or_empty_stamp_pastes_nothing() -> None:
    canvas, fig = _canvas()
    text = fig.text(50, 50, "", transform=None)
    canvas.draw()
    stamp = Stamp([text], text_anchor(text))
    stamp.capture(canvas)
    pixels = np.full((100, 200, 4), 7, dtype=np.uint8)
    stamp.paste(pixels)
    assert stamp.rgba is None and (pixels == 7).all()
    text.set_text("x")
    stamp.capture(canvas)
    text.set_visible(False)
    stamp.paste(pixels)
    assert (pixels == 7).all()


def test_a_text_stamp_is_whole_though_its_text_was_cut_by_the_edge_when_captured() -> None:
    canvas, fig = _canvas()
    text = fig.text(197.0, 40.6, "4z", transform=None, fontsize=9, color="#d95f02",
                    ha="center", va="center")  # fmt: skip
    canvas.draw()
    stamp = TextStamp(text)
    stamp.capture(canvas)
    assert text.get_position() == (197.0, 40.6)  # put back
    text.set_position((100.0, 40.6))  # whole pixels away: the same sub-pixel place
    pixels = np.full((100, 200, 4), 255, dtype=np.uint8)
    stamp.paste(pixels)
    expected = _drawn(100.0, 40.6)
    assert np.abs(pixels.astype(int) - expected.astype(int)).max() <= 1
