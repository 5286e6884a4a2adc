"""The environment's ``rgb_array`` rendering: a top-down view around the ego, drawn with numpy.

The view is north-up and centred on the ego. It draws the roads, sidewalks and crossings
of the network, the vehicles near the ego (the ego in red), the pedestrians and each
signal head in the colour it shows. The geometry and the positions come from
:mod:`explaindrive.sim.scene`, which the passenger page draws from too.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from explaindrive.sim.scene import Scene, load_scene, snapshot

VIEW_SIZE_PX = 400  # [px] the image is square
VIEW_RADIUS_M = 60.0  # [m] from the ego to the image's edges
PERSON_RADIUS_M = 0.5  # [m]
SIGNAL_RADIUS_M = 1.5  # [m]

Colour = tuple[int, int, int]
COLOURS: dict[str, Colour] = {
    "background": (64, 92, 64),
    "road": (96, 96, 96),
    "internal": (96, 96, 96),
    "sidewalk": (176, 172, 160),
    "crossing": (236, 236, 236),
    "vehicle": (66, 126, 220),
    "ego": (220, 40, 40),
    "person": (250, 160, 20),
    "green": (20, 200, 60),
    "yellow": (240, 210, 0),
    "red": (230, 0, 0),
    "off": (40, 40, 40),
}


class Canvas:
    """An RGB image over a square of the plane, centred on a point.

    Args:
        centre: ``(x, y)`` [m] at the image's centre.
        size_px: the image's width and height [px].
        radius_m: from the centre to the image's edges [m].
    """

    def __init__(self, centre: tuple[float, float], size_px: int, radius_m: float) -> None:
        self.size_px = size_px
        self.m_per_px = 2.0 * radius_m / size_px
        self.x0 = centre[0] - radius_m  # [m] the left edge
        self.y1 = centre[1] + radius_m  # [m] the top edge
        self.image = np.empty((size_px, size_px, 3), dtype=np.uint8)
        self.image[:] = COLOURS["background"]

    def _window(
        self, xmin: float, xmax: float, ymin: float, ymax: float
    ) -> tuple[slice, slice, NDArray[np.floating], NDArray[np.floating]] | None:
        """The pixel rows and columns covering a box [m], with their centres' coordinates."""
        c0 = max(math.floor((xmin - self.x0) / self.m_per_px), 0)
        c1 = min(math.ceil((xmax - self.x0) / self.m_per_px), self.size_px)
        r0 = max(math.floor((self.y1 - ymax) / self.m_per_px), 0)
        r1 = min(math.ceil((self.y1 - ymin) / self.m_per_px), self.size_px)
        if c0 >= c1 or r0 >= r1:
            return None
        xs = self.x0 + (np.arange(c0, c1) + 0.5) * self.m_per_px
        ys = self.y1 - (np.arange(r0, r1) + 0.5) * self.m_per_px
        return slice(r0, r1), slice(c0, c1), xs[None, :], ys[:, None]

    def segment(self, p0: tuple[float, float], p1: tuple[float, float], width_m: float,
                colour: Colour) -> None:  # fmt: skip
        """A straight band of ``width_m`` from ``p0`` to ``p1`` with round ends."""
        half = width_m / 2.0
        (ax, ay), (bx, by) = p0, p1
        win = self._window(min(ax, bx) - half, max(ax, bx) + half,
                           min(ay, by) - half, max(ay, by) + half)  # fmt: skip
        if win is None:
            return
        rows, cols, xs, ys = win
        dx, dy = bx - ax, by - ay
        length2 = dx * dx + dy * dy
        t = ((xs - ax) * dx + (ys - ay) * dy) / length2 if length2 > 0 else 0.0 * xs
        t = np.clip(t, 0.0, 1.0)
        inside = (xs - ax - t * dx) ** 2 + (ys - ay - t * dy) ** 2 <= half * half
        self.image[rows, cols][inside] = colour  # two slices: a view of the image

    def polyline(self, points: list[list[float]], width_m: float, colour: Colour) -> None:
        """Consecutive segments through ``points``."""
        for a, b in itertools.pairwise(points):
            self.segment((a[0], a[1]), (b[0], b[1]), width_m, colour)

    def disc(self, x: float, y: float, radius_m: float, colour: Colour) -> None:
        """A filled circle."""
        self.segment((x, y), (x, y), 2.0 * radius_m, colour)

    def box(self, front: tuple[float, float], angle_deg: float, length_m: float, width_m: float,
            colour: Colour) -> None:  # fmt: skip
        """A vehicle: a rectangle behind the middle of its front bumper ``front``, heading
        ``angle_deg`` (SUMO's: 0 north, clockwise)."""
        a = math.radians(angle_deg)
        ux, uy = math.sin(a), math.cos(a)  # along the heading
        cx, cy = front[0] - ux * length_m / 2.0, front[1] - uy * length_m / 2.0
        reach = math.hypot(length_m, width_m) / 2.0
        win = self._window(cx - reach, cx + reach, cy - reach, cy + reach)
        if win is None:
            return
        rows, cols, xs, ys = win
        along = (xs - cx) * ux + (ys - cy) * uy
        across = (xs - cx) * uy - (ys - cy) * ux
        inside = (np.abs(along) <= length_m / 2.0) & (np.abs(across) <= width_m / 2.0)
        self.image[rows, cols][inside] = colour


class TopDownView:
    """Draws the running simulation of one network.

    Args:
        net_file: the network the simulation runs.
        size_px: the image's width and height [px].
        radius_m: from the ego to the image's edges [m].
    """

    def __init__(
        self, net_file: Path, size_px: int = VIEW_SIZE_PX, radius_m: float = VIEW_RADIUS_M
    ) -> None:
        self.net_file = Path(net_file)
        self.size_px = size_px
        self.radius_m = radius_m
        self.scene: Scene = load_scene(self.net_file)
        self._centre = self._middle()

    def _middle(self) -> tuple[float, float]:
        xmin, ymin, xmax, ymax = self.scene.bounds
        return (xmin + xmax) / 2.0, (ymin + ymax) / 2.0

    def __call__(self, api: Any) -> NDArray[np.uint8]:
        """The view of the current step, ``(size_px, size_px, 3)`` uint8; centred where the
        ego was last seen (the network's middle before it entered)."""
        # objects up to the image's corners
        now = snapshot(api, self.scene, radius_m=self.radius_m * math.sqrt(2.0) + 10.0)
        if now["ego"] is not None:
            self._centre = (now["ego"]["x"], now["ego"]["y"])
        canvas = Canvas(self._centre, self.size_px, self.radius_m)
        for kind in ("sidewalk", "internal", "road"):
            for lane in self.scene.lanes:
                if lane["kind"] == kind and self._near(lane["shape"]):
                    canvas.polyline(lane["shape"], lane["width"], COLOURS[kind])
        for crossing in self.scene.crossings:
            if self._near(crossing["shape"]):
                canvas.polyline(crossing["shape"], crossing["width"], COLOURS["crossing"])
        for signal in now["signals"]:
            canvas.disc(signal["x"], signal["y"], SIGNAL_RADIUS_M, COLOURS[signal["colour"]])
        for person in now["persons"]:
            canvas.disc(person["x"], person["y"], PERSON_RADIUS_M, COLOURS["person"])
        for vehicle in now["vehicles"]:
            self._vehicle(canvas, vehicle, COLOURS["vehicle"])
        if now["ego"] is not None:
            self._vehicle(canvas, now["ego"], COLOURS["ego"])
        return canvas.image

    def _near(self, shape: list[list[float]]) -> bool:
        """Whether a shape's bounding box reaches into the view."""
        cx, cy = self._centre
        r = self.radius_m + 10.0
        xs = [p[0] for p in shape]
        ys = [p[1] for p in shape]
        return min(xs) <= cx + r and max(xs) >= cx - r and min(ys) <= cy + r and max(ys) >= cy - r

    @staticmethod
    def _vehicle(canvas: Canvas, v: dict[str, Any], colour: Colour) -> None:
        canvas.box((v["x"], v["y"]), v["angle"], v["length"], v["width"], colour)
