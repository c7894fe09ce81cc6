"""Stamps: artists that only move, rendered once and pasted at each frame of a movie.

Matplotlib lays out and rasterises a text at every draw, about a quarter of a
millisecond each; a movie frame of a run has a dozen texts that never change
(the body axes' ``x``, ``y``, ``z``, the bumper numbers, the compass), which
took a third of a frame's drawing. A :class:`Stamp` draws its artists once
onto a cleared canvas and keeps their pixels with the coverage as alpha; each
frame then pastes them where the artists are now (their anchor's display
position, rounded to the pixel as Agg places a text), in their turn of the
drawing order, so what lies over them still does. A pasted text differs from
a fresh draw by at most a pixel in place (Agg rounds a text's own position; the
stamp rounds its anchor's) and, at its edges, by the anti-aliasing of a glyph
drawn at another sub-pixel offset (a third of full scale at most, seen on a
few tens of a frame's pixels); text drawn in place at the same offset is the same
to a unit of rounding.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from matplotlib.artist import Artist
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.text import Text

__all__ = ["Stamp", "TextStamp", "text_anchor"]


def text_anchor(text: Text) -> Callable[[], tuple[float, float]]:
    """The display position (pixels from the lower left) of ``text``'s anchor, when called."""

    def anchor() -> tuple[float, float]:
        x, y = text.get_transform().transform(text.get_position())
        return float(x), float(y)

    return anchor


class Stamp:
    """The pixels of ``artists``, which only move with ``anchor`` (display pixels).

    Parameters
    ----------
    artists : sequence of Artist
        Drawn together by :meth:`capture`; their look (text, colours, size)
        must not change afterwards, only their place.
    anchor : callable
        Their reference point's display position now, ``(x, y)`` in pixels
        from the figure's lower left.
    """

    def __init__(
        self, artists: Sequence[Artist], anchor: Callable[[], tuple[float, float]]
    ) -> None:
        self.artists = list(artists)
        self.anchor = anchor
        self.rgba: np.ndarray | None = None  # (h, w, 4) uint8, colour with coverage as alpha
        self.offset = (0.0, 0.0)  # of the pixels' top left from the anchor (columns, rows down)

    def capture(self, canvas: FigureCanvasAgg) -> None:
        """Draw the artists alone on ``canvas``'s cleared renderer; keep their pixels.

        Leaves the canvas cleared but for them: the caller restores its background.
        """
        renderer = canvas.get_renderer()
        renderer.clear()  # transparent: Agg blends the artists' colours with alpha 0
        for artist in self.artists:
            if artist.get_visible():
                artist.draw(renderer)
        pixels = np.asarray(canvas.buffer_rgba())
        rows, cols = np.nonzero(pixels[:, :, 3])
        if rows.size == 0:  # nothing drawn (hidden, empty or off the canvas)
            self.rgba = None
            return
        r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
        self.rgba = pixels[r0:r1, c0:c1].copy()
        x, y = self.anchor()
        self.offset = (c0 - x, r0 - (pixels.shape[0] - y))

    def paste(self, pixels: np.ndarray) -> None:
        """Blend the kept pixels onto ``pixels`` (the canvas's RGBA, opaque) where the anchor is."""
        if self.rgba is None or not self.artists[0].get_visible():
            return
        x, y = self.anchor()
        if not (np.isfinite(x) and np.isfinite(y)):
            return
        height, width = pixels.shape[:2]
        c0 = int(round(x + self.offset[0]))
        r0 = int(round(height - y + self.offset[1]))
        h, w = self.rgba.shape[:2]
        top, left = max(r0, 0), max(c0, 0)
        bottom, right = min(r0 + h, height), min(c0 + w, width)
        if top >= bottom or left >= right:
            return
        src = self.rgba[top - r0 : bottom - r0, left - c0 : right - c0]
        dst = pixels[top:bottom, left:right, :3]
        alpha = src[:, :, 3:4].astype(np.uint16)
        mixed = src[:, :, :3] * alpha + dst * (255 - alpha) + 127
        dst[...] = mixed // 255


class TextStamp(Stamp):
    """A text's stamp, captured with the text moved to the middle of its axes (of the
    canvas without axes) by whole pixels, so that an edge never cuts what is kept and
    its sub-pixel place is kept too; then put back."""

    def __init__(self, text: Text) -> None:
        super().__init__([text], text_anchor(text))
        self.text = text

    def capture(self, canvas: FigureCanvasAgg) -> None:
        text = self.text
        if text.axes is not None:
            middle = (
                text.axes.bbox.x0 + 0.5 * text.axes.bbox.width,
                (text.axes.bbox.y0 + 0.5 * text.axes.bbox.height),
            )
        else:
            width, height = canvas.get_width_height()
            middle = 0.5 * width, 0.5 * height
        x, y = self.anchor()
        if np.isfinite(x) and np.isfinite(y):  # whole pixels: the sub-pixel offset kept
            middle = (math.floor(middle[0]) + x - math.floor(x),
                      math.floor(middle[1]) + y - math.floor(y))  # fmt: skip
        saved = text.get_position()
        text.set_position(text.get_transform().inverted().transform(middle))
        try:
            super().capture(canvas)
        finally:
            text.set_position(saved)
