"""Drawing a :class:`~quadimpact.viz.scene.Scene` on a matplotlib Axes.

:class:`SceneArtists` creates every artist once (lines, patches, texts) and
:meth:`SceneArtists.update` moves them to another instant by changing their
data in place, which is what makes animations fast (no artist is created or
removed per frame). Coordinates on the Axes are the camera's screen
coordinates in metres with ``aspect = "equal"``, so scaling is equal in every
direction; altitude is up.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection
from matplotlib.lines import Line2D
from matplotlib.patches import FancyArrowPatch, Polygon

from quadimpact.core import layout as L
from quadimpact.core import shape_slots as SHP
from quadimpact.viz.camera import Camera
from quadimpact.viz.scene import Scene
from quadimpact.viz.world_drawing import plane_axes, plane_grid, shape_lines

__all__ = ["FORCE_COLOR", "GROUND_COLOR", "SceneArtists", "WALL_COLOR", "wall_range"]

WALL_COLOR = "#9aa5b1"
GROUND_COLOR = "#c8b48a"
FORCE_COLOR = "#7b2cbf"
BODY_COLOR = "#222222"
AXIS_COLORS = ("#444444", "#444444", "#444444")
MAX_CONTACTS = 16  # drawn at once (4 bumpers x 2 surfaces, 8 features x 2...)
#: Least distance of a bumper number from any bumper ring on the picture, in picture heights.
LABEL_CLEARANCE = 0.045
WALL_WIDTH_M = 1.0  # walls: a panel this wide, from the view centre away from the camera


def wall_range(
    normal: np.ndarray, forward: np.ndarray, right: np.ndarray | None = None
) -> tuple[float, float] | None:
    """Extent of a wall panel along its horizontal axis, from the view centre.

    A wall (a steep plane) is drawn cut by the vertical plane through the view
    centre that contains the wall normal, and only one half is drawn, so that
    the cut edge is where the vehicle meets the wall. The half is the one on
    the side of the picture away from the vehicle: the vehicle stands out from
    the wall along the wall normal, which the camera sees pointing to one side
    of the picture (``right``: the screen's right, NED), so the other side's
    half lies beside the vehicle, not behind it, and the contact reads at the
    edge. Seen straight on (the normal along the view), the half beyond the
    view centre. Flat planes (the ground): ``None`` (a square around the centre).
    """
    m = np.asarray(normal, dtype=float)
    if abs(m[2]) / np.linalg.norm(m) > 0.7:
        return None
    e1, _ = plane_axes(m)
    side = float(e1 @ right) * float(m @ right) if right is not None else 0.0
    if abs(side) > 1e-3:  # the normal shows on screen: the half on the other side of it
        return (0.0, WALL_WIDTH_M) if side < 0.0 else (-WALL_WIDTH_M, 0.0)
    return (0.0, WALL_WIDTH_M) if float(e1 @ forward) > 0.0 else (-WALL_WIDTH_M, 0.0)


class SceneArtists:
    """The artists of one view of a scene, updated in place.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        Axes to draw on (its limits, aspect and frame are set here).
    scene : Scene
        The run.
    camera : Camera
        View direction, following mode and picture height.
    aspect : float
        Width / height of the picture (sets the x limits).
    labels : bool
        Draw the bumper numbers and body axis names.
    compass : bool
        Draw the small inertial triad (X, Y, up) in a corner.
    linewidth : float
        Width of the bumper rims (others scale with it).
    """

    def __init__(
        self,
        ax: Axes,
        scene: Scene,
        camera: Camera,
        aspect: float = 1.0,
        labels: bool = True,
        compass: bool = True,
        linewidth: float = 2.0,
    ) -> None:
        self.ax = ax
        self.scene = scene
        self.camera = camera
        self.half_h = 0.5 * camera.span_m
        self.half_w = self.half_h * aspect
        ax.set_xlim(-self.half_w, self.half_w)
        ax.set_ylim(-self.half_h, self.half_h)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xticks([])
        ax.set_yticks([])
        for spine in ax.spines.values():
            spine.set_color("#bbbbbb")
        ax.set_facecolor("white")
        right, up, forward = camera.basis()
        self._forward = forward
        lw = linewidth

        self._add_surfaces(lw, right, forward)
        self._add_vehicle(lw, labels)
        self._add_contacts(lw)
        self.show_force_text = labels

        self.compass: list = []
        if compass:
            self._draw_compass(right, up)

    # ------------------------------------------------------------ the artists
    def _add_surfaces(self, lw: float, right: np.ndarray, forward: np.ndarray) -> None:
        """The planes (contact surfaces and the ground, for reference) and the solids' lines."""
        ax, scene = self.ax, self.scene
        # planes: the contact surfaces, and the ground plane for reference
        self.planes: list[tuple[np.ndarray, np.ndarray, Any, Polygon, LineCollection]] = []
        sf = scene.surf
        planes = [
            (sf[k, SHP.SH_POINT : SHP.SH_POINT + 3], sf[k, SHP.SH_NORMAL : SHP.SH_NORMAL + 3],
             sf[k, SHP.SH_IS_GROUND] > 0.5, s.name)
            for k, s in enumerate(scene.surfaces)
            if int(sf[k, SHP.SH_KIND]) == L.SHAPE_PLANE
        ]  # fmt: skip
        if not any(getattr(s, "is_ground", False) for s in scene.surfaces):
            planes.append(((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), True, ""))
        self._cuts = scene.first_contact_points()
        for point, normal, is_ground, name in planes:
            p = np.asarray(point, float)
            m = np.asarray(normal, float) / np.linalg.norm(normal)
            color = GROUND_COLOR if is_ground else WALL_COLOR
            # a camera on the free side of the plane sees it behind the vehicle
            in_front = float(-forward @ m) < 0.0
            z = 10 if in_front else 0.5
            poly = Polygon(
                np.zeros((4, 2)),
                closed=True,
                facecolor=color,
                edgecolor="#59636e",
                linewidth=0.8 * lw / 2,
                alpha=0.3 if in_front else 0.45,
                zorder=z,
            )
            grid = LineCollection(
                [], colors="#6b7785", linewidths=0.4 * lw / 2, alpha=0.35, zorder=z
            )
            ax.add_patch(poly)
            ax.add_collection(grid)
            self.planes.append((p, m, (wall_range(m, forward, right), name), poly, grid))
        # cylinders and boxes: their rims, generators and edges
        self.solids = [
            k
            for k in range(scene.surf.shape[0])
            if int(scene.surf[k, SHP.SH_KIND]) != L.SHAPE_PLANE
        ]
        self.solid_lines = LineCollection(
            [], colors="#59636e", linewidths=0.9 * lw / 2, alpha=0.8, zorder=2
        )
        ax.add_collection(self.solid_lines)

    def _add_vehicle(self, lw: float, labels: bool) -> None:
        """The vehicle: rotor discs, arms, hub, body axes and the features with their names."""
        ax, scene = self.ax, self.scene
        self.discs = [
            Polygon(
                np.zeros((2, 2)),
                closed=True,
                facecolor="#888888",
                edgecolor="#777777",
                alpha=0.18,
                linewidth=0.5 * lw / 2,
                zorder=3,
            )
            for _ in range(4)
        ]
        for p in self.discs:
            ax.add_patch(p)
        self.arms = LineCollection([], colors=BODY_COLOR, linewidths=1.6 * lw / 2, zorder=4)
        ax.add_collection(self.arms)
        (self.hub,) = ax.plot([], [], color=BODY_COLOR, linewidth=1.2 * lw / 2, zorder=4)
        self.axes_lines = [
            ax.plot([], [], color=AXIS_COLORS[k], linewidth=1.0 * lw / 2, zorder=6)[0]
            for k in range(3)
        ]
        self.axes_text = [
            ax.text(
                0,
                0,
                name,
                fontsize=7,
                color="#444444",
                ha="center",
                va="center",
                zorder=7,
                visible=labels,
            )
            for name in ("x", "y", "z")
        ]
        d = scene.drawing
        self.circles = [
            ax.plot(
                [], [], color=d.colors[int(f)], linewidth=lw if len(d.circles) <= 8 else 0.6 * lw,
                zorder=5, solid_capstyle="round",
            )[0]
            for f in d.line_feature
        ]  # fmt: skip
        self.labels = [
            ax.text(
                0,
                0,
                name,
                fontsize=9 if len(name) <= 2 else 7,
                fontweight="bold",
                color=d.colors[j],
                ha="center",
                va="center",
                zorder=7,
                visible=labels,
            )
            for j, name in enumerate(d.names)
        ]

    def _add_contacts(self, lw: float) -> None:
        """Per contact: its deepest point, deflection segment, force arrow and force value."""
        ax = self.ax
        # contacts: deepest point, deflection segment, force arrow, force value
        self.points: list[Line2D] = []
        self.deflections: list[Line2D] = []
        self.arrows: list[FancyArrowPatch] = []
        self.force_texts = []
        for _ in range(MAX_CONTACTS):
            (pt,) = ax.plot(
                [],
                [],
                "o",
                markersize=3.5 * lw / 2,
                markerfacecolor="black",
                markeredgecolor="white",
                markeredgewidth=0.6,
                zorder=12,
            )
            (dl,) = ax.plot([], [], color="black", linewidth=2.2 * lw / 2, zorder=11)
            arrow = FancyArrowPatch(
                (0, 0),
                (0, 0),
                arrowstyle="-|>",
                mutation_scale=10 * lw / 2,
                color=FORCE_COLOR,
                linewidth=1.6 * lw / 2,
                shrinkA=0.0,
                shrinkB=0.0,
                zorder=12,
            )
            ax.add_patch(arrow)
            txt = ax.text(0, 0, "", fontsize=7, color=FORCE_COLOR, zorder=12, va="center",
                          bbox={"boxstyle": "round,pad=0.12", "facecolor": "white",
                                "edgecolor": "none", "alpha": 0.75})  # fmt: skip
            self.points.append(pt)
            self.deflections.append(dl)
            self.arrows.append(arrow)
            self.force_texts.append(txt)

    # ------------------------------------------------------------ static parts
    def _draw_compass(self, right: np.ndarray, up: np.ndarray) -> None:
        """Inertial directions X (to the wall), Y (right) and up, in the lower left corner."""
        ax = self.ax
        size = 0.09 * 2 * self.half_h
        origin = np.array([-self.half_w + 1.3 * size, -self.half_h + 1.3 * size])
        dirs = {
            "X": np.array([1.0, 0.0, 0.0]),
            "Y": np.array([0.0, 1.0, 0.0]),
            "up": np.array([0.0, 0.0, -1.0]),
        }
        for name, v in dirs.items():
            s = np.array([v @ right, v @ up])
            tip = origin + size * s
            arrow = ax.annotate(
                "",
                xy=tip,
                xytext=origin,
                arrowprops={
                    "arrowstyle": "-|>",
                    "color": "#555555",
                    "lw": 0.8,
                    "mutation_scale": 7,
                },
                zorder=13,
            )
            self.compass.append(arrow)
            if np.hypot(*s) > 0.15:
                label = origin + size * s + 0.4 * size * s / np.hypot(*s)
                self.compass.append(
                    ax.text(
                        label[0],
                        label[1],
                        name,
                        fontsize=6.5,
                        color="#555555",
                        ha="center",
                        va="center",
                        zorder=13,
                    )
                )

    # ------------------------------------------------------------ per frame
    def update(self, t: float) -> list:
        """Move every artist to time ``t``; return the artists changed."""
        scene, cam = self.scene, self.camera
        fr = scene.frame(t)
        target = scene.target(t, cam)

        def P(points: np.ndarray) -> np.ndarray:
            return cam.project(points, target)

        half = 2.5 * max(self.half_w, self.half_h)
        for p, m, (width, name), poly, grid in self.planes:
            centre = target
            if width is not None and name in self._cuts:  # cut where the vehicle met it
                e1 = plane_axes(m)[0]
                centre = target + float((self._cuts[name] - target) @ e1) * e1
            outline, segs = plane_grid(p, m, centre, half, step=0.1, range1=width)
            poly.set_xy(P(outline[:4]))
            grid.set_segments(list(P(segs)) if len(segs) else [])

        if self.solids:
            segs = [
                P(line) for k in self.solids for line in shape_lines(scene.surf[k], target, half)
            ]
            self.solid_lines.set_segments(segs)
        depth = cam.depth(fr.circles.mean(axis=1), target)
        order = np.argsort(-depth)  # far first
        if scene.drawing.vehicle.features is None:  # the four bumpers: numbers off the rings
            rings = np.stack([P(fr.circles[j]) for j in range(4)])
            label_xy = self._inside(
                place_labels(rings, P(fr.label_points), LABEL_CLEARANCE * 2 * self.half_h)
            )
        else:
            label_xy = self._inside(P(fr.label_points))
        for rank, j in enumerate(order):
            self.circles[j].set_data(*P(fr.circles[j]).T)
            self.circles[j].set_zorder(5 + 0.01 * rank)
        for j in range(4):
            self.discs[j].set_xy(P(fr.discs[j]))
        for j, label in enumerate(self.labels):
            label.set_position(label_xy[j])
        self.arms.set_segments(list(P(fr.arms)))
        self.hub.set_data(*P(fr.hub).T)
        for k in range(3):
            seg = P(fr.axes[k])
            self.axes_lines[k].set_data(*seg.T)
            tip = seg[1] + 0.18 * (seg[1] - seg[0])
            self.axes_text[k].set_position(tip)

        n = min(len(fr.contacts), MAX_CONTACTS)
        for i in range(MAX_CONTACTS):
            on = i < n
            for art in (self.points[i], self.deflections[i], self.arrows[i], self.force_texts[i]):
                art.set_visible(on)
            if not on:
                continue
            c = fr.contacts[i]
            pc, ps, tip = P(c.point), P(c.surface_point), P(c.arrow_tip)
            self.points[i].set_data([pc[0]], [pc[1]])
            self.deflections[i].set_data([pc[0], ps[0]], [pc[1], ps[1]])
            self.deflections[i].set_color(scene.drawing.colors[c.bumper - 1])
            self.arrows[i].set_positions(tuple(ps), tuple(tip))
            xy, ha = self._force_text_place(ps, tip, label_xy)
            self.force_texts[i].set_position(xy)
            self.force_texts[i].set_horizontalalignment(ha)
            show = self.show_force_text and c.force_n >= 0.05
            self.force_texts[i].set_text(f"{c.force_n:.1f} N" if show else "")
        return self.artists()

    def _inside(self, xy: np.ndarray) -> np.ndarray:
        """Screen points moved just inside the frame (a label half out of it is cut)."""
        margin = 0.035 * 2 * self.half_h
        out = np.array(xy, dtype=float)
        out[..., 0] = np.clip(out[..., 0], -self.half_w + margin, self.half_w - margin)
        out[..., 1] = np.clip(out[..., 1], -self.half_h + margin, self.half_h - margin)
        return out

    def _force_text_place(
        self, base: np.ndarray, tip: np.ndarray, labels: np.ndarray
    ) -> tuple[np.ndarray, str]:
        """Where a force value goes: beside its arrow, on the side away from the bumper numbers.

        The two sides of the arrow's middle are tried; the one farther from the
        nearest bumper number wins (so the value never sits on a number), and
        it is kept inside the frame. Returns the point and the alignment.
        """
        d = np.asarray(tip, float) - np.asarray(base, float)
        length = float(np.hypot(*d))
        d = d / length if length > 1e-9 else np.array([0.0, 1.0])
        perp = np.array([-d[1], d[0]])
        mid = 0.5 * (np.asarray(base, float) + np.asarray(tip, float))
        gap = 0.03 * 2 * self.half_h
        best = None
        for sign in (1.0, -1.0):
            p = self._inside(mid + sign * gap * perp)
            clearance = float(np.min(np.hypot(*(labels - p).T))) if len(labels) else np.inf
            if best is None or clearance > best[0]:
                best = (clearance, p, sign * perp[0])
        _, point, side = best
        return point, ("left" if side >= 0.0 else "right")

    def constant_texts(self) -> list:
        """The texts that only move (the body axes' names, the bumper numbers): visible ones."""
        return [t for t in (*self.axes_text, *self.labels) if t.get_visible()]

    def artists(self) -> list:
        """Every artist this view draws (for blitting: all change between frames
        or lie over ones that do), in drawing order (by zorder)."""
        arts = [a for _p, _m, _w, poly, grid in self.planes for a in (poly, grid)]
        arts += [self.solid_lines]
        arts += [*self.discs, self.arms, self.hub, *self.axes_lines, *self.axes_text]
        arts += [*self.circles, *self.labels, *self.points, *self.deflections, *self.arrows]
        arts += [*self.force_texts, *self.compass]
        return sorted(arts, key=lambda a: a.get_zorder())


def place_labels(rings: np.ndarray, default: np.ndarray, clearance: float) -> np.ndarray:
    """Where the four bumper numbers go on the picture: off every ring, each by its own.

    Parameters
    ----------
    rings : numpy.ndarray, shape (4, N, 2)
        The bumper rings as drawn (picture coordinates).
    default : numpy.ndarray, shape (4, 2)
        The 3D placement's points (1.3 bumper radii out from each centre),
        projected: where a number goes when it is clear there.
    clearance : float
        The least distance of a number from any ring point and from the other
        numbers (picture units).

    Returns
    -------
    numpy.ndarray, shape (4, 2)
        For each bumper: its default point if that is clear of every ring;
        otherwise, among points just outside its own ring in directions
        around the one from the vehicle's centre through the ring's, the first
        clear one (or the one farthest from the rings and numbers).
    """
    rings = np.asarray(rings, dtype=float)
    centres = rings.mean(axis=1)
    middle = centres.mean(axis=0)
    every = rings.reshape(-1, 2)
    out = np.array(default, dtype=float)
    placed: list[np.ndarray] = []
    for j in range(rings.shape[0]):

        def room(p: np.ndarray) -> float:
            d = float(np.min(np.hypot(*(every - p).T)))
            if placed:
                d = min(d, float(np.min(np.hypot(*(np.array(placed) - p).T))))
            return d

        if room(out[j]) >= clearance:
            placed.append(out[j])
            continue
        away = centres[j] - middle
        if np.hypot(*away) < 1e-12:
            away = out[j] - centres[j]
        base = math.atan2(away[1], away[0]) if np.hypot(*away) > 1e-12 else 0.0
        best, best_room = out[j], room(out[j])
        for step in (0, 1, -1, 2, -2, 3, -3, 4, -4, 5, -5, 6):
            angle = base + step * math.pi / 6
            d = np.array([math.cos(angle), math.sin(angle)])
            reach = float(np.max((rings[j] - centres[j]) @ d))
            p = centres[j] + (reach + clearance) * d
            r = room(p)
            if r >= clearance:
                best, best_room = p, r
                break
            if r > best_room:
                best, best_room = p, r
        out[j] = best
        placed.append(best)
    return out
