"""The Exudyn visual system of a layout: one 2D rigid body per rotating inertia, ground parts, camera,
and pictures from Exudyn's software raytracer (no display) or its OpenGL viewer (display needed).

This module and ``gearbody.engine`` are the only places that import Exudyn. The visual system is a
separate, kinematic model: its coordinates are set from pose rows (:mod:`gearbody.render.poses`)
and it is never integrated.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from .layout import Box, Cylinder, GearShape, Layout, Prism
from .poses import RenderError

VIEWS = {  # azimuth, elevation in degrees: the eye's direction from the drive's centre
    "iso": (125.0, 35.0),
    "front": (180.0, 0.0),
    "back": (0.0, 0.0),
    "side": (-90.0, 0.0),
    "top": (0.0, 89.0),
}
"""The camera directions by name (``RenderOptions.view``): azimuth and elevation in degrees."""


FRAMES = ("drive", "gears", "mesh")
"""What the camera fits: the whole drive, the gears, or the first stage's mesh (pitch point +- 6 modules)."""


@dataclass
class RenderOptions:
    """Picture settings; sizes in pixels, angles in degrees."""

    width_px: int = 800
    height_px: int = 600
    view: str = "iso"
    azimuth_deg: float | None = None
    elevation_deg: float | None = None
    zoom: float = 1.0
    frame: str = "drive"  # what the camera fits: "drive" (everything), "gears", or "mesh" (stage 1's teeth)
    machines: bool | None = None  # draw motor and driven machine; None: only when frame == "drive"
    background: tuple[float, float, float] = (1.0, 1.0, 1.0)
    housing: bool | None = None  # None: as the scenario's visual.housing
    threads: int = 0  # raytracer threads; 0 = all cores

    def check(self) -> None:
        for name in ("width_px", "height_px"):
            v = getattr(self, name)
            if not (isinstance(v, int) and 16 <= v <= 8192):
                raise RenderError(f"{name} = {v!r}: must be a whole number of pixels in [16, 8192]")
        if self.view not in VIEWS:
            raise RenderError(f"view = {self.view!r}: must be one of {', '.join(VIEWS)}")
        if not 0.05 <= self.zoom <= 50:
            raise RenderError(f"zoom = {self.zoom:g}: must lie in [0.05, 50] (1 = whole drive)")
        if self.frame not in FRAMES:
            raise RenderError(f"frame = {self.frame!r}: must be one of {', '.join(map(repr, FRAMES))}")
        if self.elevation_deg is not None and not -90 <= self.elevation_deg <= 90:
            raise RenderError(f"elevation_deg = {self.elevation_deg:g}: must lie in [-90, 90]")
        if any(not 0 <= c <= 1 for c in self.background):
            raise RenderError(f"background = {self.background}: RGB components in [0, 1]")


def camera_rotation(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """World -> view rotation: rows are the screen's right, up and towards-the-eye directions (world
    y is up, gear axes along z, the motor on the -z side)."""
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    eye = np.array([math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az)])
    right = np.array([math.cos(az), 0.0, -math.sin(az)])
    up = np.cross(eye, right)
    return np.array([right, up, eye])


def _rotation_vector(R: np.ndarray) -> list[float]:
    from exudyn.rigidBodyUtilities import RotationMatrix2RotationVector

    return list(RotationMatrix2RotationVector(R))


def _outline_gear_graphics(gear: GearShape):
    """A gear from gearbody's involute outline: external with its bore, or internal in its rim."""
    import exudyn.graphics as gr

    from .planetary import tooth_outline

    m, r = gear.module_m, gear.pitch_radius_m
    r_out, r_in = (r + 1.25 * m, r - m) if gear.internal else (r + m, r - 1.25 * m)
    outline = tooth_outline(gear.teeth, m, gear.pressure_angle_deg, r_out, r_in)
    # an internal gear's lobes are its tooth spaces, half a pitch from its teeth
    offset = gear.first_tooth_rad + (math.pi / gear.teeth if gear.internal else 0.0)
    c, s = math.cos(offset), math.sin(offset)
    points = (outline @ np.array([[c, s], [-s, c]])).tolist()
    n = len(points)
    segments = [[i, (i + 1) % n] for i in range(n)]
    circle = gear.rim_radius_m if gear.internal else gear.bore_radius_m
    if circle > 0:
        a = np.linspace(0.0, 2 * math.pi, 64, endpoint=False)
        ring = np.column_stack([circle * np.cos(a), circle * np.sin(a)])
        if not gear.internal:  # a hole: clockwise
            ring = ring[::-1]
        points += ring.tolist()
        segments += [[n + i, n + (i + 1) % len(ring)] for i in range(len(ring))]
    if gear.internal:  # the outline bounds a hole: clockwise
        segments = [[j, i] for i, j in segments[:n]] + segments[n:]
    return [
        gr.SolidExtrusion(
            points,
            segments,
            gear.face_width_m,
            pOff=[0, 0, gear.z_m - gear.face_width_m / 2],
            color=list(gear.colour),
        )
    ]


def _gear_graphics(gear: GearShape):
    import exudyn.graphics as gr
    import exudyn.machines as machines

    from .planetary import tooth_outline

    if gear.outline == "gearbody":
        return _outline_gear_graphics(gear)

    geometry = machines.InvoluteGear(
        module=gear.module_m, nTeeth=gear.teeth, pressureAngleDeg=gear.pressure_angle_deg
    )
    try:
        points = np.asarray(geometry.GenerateGear())  # tooth 0 centred on +x
    except ValueError:  # Exudyn's generator leaves no root between many teeth (96 at 20 deg): gearbody's
        m, r = gear.module_m, gear.pitch_radius_m
        points = tooth_outline(gear.teeth, m, gear.pressure_angle_deg, r + m, r - 1.25 * m)
        return [*_outline_gear_graphics(gear), *_tooth_marks(gear, points)]
    rot = _rot_z(gear.first_tooth_rad)
    out = [
        gr.InvoluteGear(
            geometry,
            gear.face_width_m,
            centerPoint=[0, 0, gear.z_m],
            rotationMatrix=rot,
            radius=gear.bore_radius_m,
            color=list(gear.colour),
            nTilesCylinder=24,
        )
    ]
    return [*out, *_tooth_marks(gear, points)]


def _tooth_marks(gear: GearShape, points: np.ndarray) -> list:
    """The gear's marked (damaged, pitted) teeth in their colours, cut from its outline ``points`` (n, 2)
    with tooth 0 centred on +x."""
    import exudyn.graphics as gr

    if not gear.marked_teeth:
        return []
    half = math.pi / gear.teeth
    ang = np.arctan2(points[:, 1], points[:, 0])
    sel = points[np.abs(ang) < half]
    sel = sel[np.argsort(np.arctan2(sel[:, 1], sel[:, 0]))] * 1.004  # stands 0.4 % proud of the gear
    r_in = 0.97 * gear.root_radius_m  # the tooth only: its root edge hides in the rim
    inner = [
        [r_in * math.cos(half), r_in * math.sin(half)],
        [r_in * math.cos(-half), r_in * math.sin(-half)],
    ]
    poly = np.vstack([sel, inner])
    n = len(poly)
    segments = [[i, (i + 1) % n] for i in range(n)]
    out = []
    for angle, colour in gear.marked_teeth:
        width = 1.02 * gear.face_width_m
        out.append(
            gr.SolidExtrusion(
                poly.tolist(),
                segments,
                width,
                rot=_rot_z(angle),
                pOff=[0, 0, gear.z_m - width / 2],
                color=list(colour),
            )
        )
    return out


def _rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _part_graphics(part, offset=(0.0, 0.0)):
    import exudyn.graphics as gr

    if isinstance(part, GearShape):
        return _gear_graphics(part)
    if isinstance(part, Cylinder):
        x, y = part.x_m - offset[0], part.y_m - offset[1]
        kw = {"radiusInner": part.inner_radius_m} if part.inner_radius_m > 0 else {}
        return [
            gr.Cylinder(
                pAxis=[x, y, part.z0_m],
                vAxis=[0, 0, part.z1_m - part.z0_m],
                radius=part.radius_m,
                color=list(part.colour),
                nTiles=32,
                **kw,
            )
        ]
    if isinstance(part, Prism):
        points = [list(p) for p in part.outline_m]
        n = len(points)
        segments = [[i, (i + 1) % n] for i in range(n)]
        if part.hole_radius_m > 0:
            a = np.linspace(2 * math.pi, 0.0, 48, endpoint=False)  # clockwise: a hole
            points += [[part.hole_radius_m * math.cos(t), part.hole_radius_m * math.sin(t)] for t in a]
            segments += [[n + i, n + (i + 1) % 48] for i in range(48)]
        return [
            gr.SolidExtrusion(
                points, segments, part.z1_m - part.z0_m, pOff=[0, 0, part.z0_m], color=list(part.colour)
            )
        ]
    if isinstance(part, Box):
        c = part.centre_m
        return [
            gr.Brick(
                centerPoint=[c[0] - offset[0], c[1] - offset[1], c[2]],
                size=list(part.size_m),
                color=list(part.colour),
            )
        ]
    raise TypeError(f"cannot draw {type(part).__name__}")


class VisualSystem:
    """Exudyn system container holding the drawn drive; ``set_pose(row)`` moves it."""

    def __init__(
        self,
        layout: Layout,
        options: RenderOptions | None = None,
        *,
        bodies: bool = True,
        ground: bool = True,
    ):
        import exudyn as exu
        import exudyn.itemInterface as ii

        self.exu = exu
        self.layout = layout
        self.options = options or RenderOptions()
        self.options.check()
        o = self.options
        self.show_machines = o.machines if o.machines is not None else o.frame == "drive"
        self.SC = exu.SystemContainer()
        self.mbs = self.SC.AddSystem()
        statics = []
        if ground:
            statics += [g for p in layout.ground for g in _part_graphics(p)]
            if self.show_machines:
                statics += [g for p in layout.machines for g in _part_graphics(p)]
            housing = self.options.housing if self.options.housing is not None else layout.show_housing
            if housing and layout.housing is not None:
                statics += _part_graphics(layout.housing)
        self.mbs.AddObject(ii.ObjectGround(visualization=ii.VObjectGround(graphicsData=statics)))
        for b in layout.bodies:
            node = self.mbs.AddNode(
                ii.NodeRigidBody2D(referenceCoordinates=[b.axis_xy_m[0], b.axis_xy_m[1], 0.0])
            )
            drawn = bodies and (self.show_machines or b.name not in ("motor", "machine"))
            graphics = [g for p in b.parts for g in _part_graphics(p)] if drawn else []
            self.mbs.AddObject(
                ii.ObjectRigidBody2D(
                    nodeNumber=node,
                    mass=1.0,
                    inertia=1.0,
                    visualization=ii.VObjectRigidBody2D(graphicsData=graphics),
                )
            )
        self.mbs.Assemble()
        self._settings()

    def _settings(self) -> None:
        o, vs = self.options, self.SC.visualizationSettings
        vs.view0.window.renderWindowSize = [o.width_px, o.height_px]
        vs.general.showSolverInformation = False
        vs.general.showSolutionInformation = False
        vs.general.showSolverTime = False
        vs.view0.window.showComputationInfo = False
        vs.view0.scene.drawCoordinateSystem = False
        vs.view0.scene.drawWorldBasis = False
        vs.general.useGradientBackground = False
        vs.general.backgroundColor = [*o.background, 1.0]
        vs.general.autoFitScene = False
        vs.nodes.show = False
        vs.bodies.show = True
        vs.raytracer.numberOfThreads = o.threads or (os.cpu_count() or 1)
        vs.raytracer.verbose = 0
        vs.raytracer.advanced.showText = False
        vs.openGL.multiSampling = 1
        vs.openGL.light0.position = [-2.0, 6.0, 6.0, 0.0]

    def set_camera(self, pose: np.ndarray | None = None) -> None:
        """Fit the camera to the framed parts (``pose``: where a revolving mesh is, frame "mesh")."""
        o = self.options
        az, el = VIEWS[o.view]
        az = o.azimuth_deg if o.azimuth_deg is not None else az
        el = o.elevation_deg if o.elevation_deg is not None else el
        R = camera_rotation(az, el)
        if o.frame == "mesh":
            lo, hi = (np.array(v) for v in self.layout.mesh_bounds_m(pose=pose))
        else:
            lo, hi = (np.array(v) for v in self.layout.bounds_m(gears_only=o.frame == "gears"))
        centre = 0.5 * (lo + hi)
        # visible height: the box's extent on screen (projected corners), with a small margin
        corners = np.array(
            [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
        )
        screen = (corners - centre) @ R.T
        aspect = o.width_px / o.height_px
        # Exudyn's zoom is half the visible height (measured)
        height = 0.5 * max(np.ptp(screen[:, 1]), np.ptp(screen[:, 0]) / aspect) * 1.08 / o.zoom
        # an inactive renderer ignores SetModelView until its state exists; ZoomAll creates it
        self.SC.renderer.ZoomAll()
        self.SC.renderer.SetModelView(
            zoom=float(height), rotationVector=_rotation_vector(R), centerPoint=[float(c) for c in R @ centre]
        )  # in view axes (measured)

    def set_pose(self, row: np.ndarray, time_s: float = 0.0) -> None:
        """Place every body: row = [x, y, theta] per body, offsets from its axis."""
        q = [float(v) for v in row]  # node coordinates are offsets from the reference (the axis)
        # the raytracer without an open renderer draws the Current configuration (measured)
        for cfg in (self.exu.ConfigurationType.Current, self.exu.ConfigurationType.Visualization):
            self.mbs.systemData.SetODE2Coordinates(q, configuration=cfg)
            self.mbs.systemData.SetTime(float(time_s), cfg)
        self.mbs.SendRedrawSignal()

    def image(self, raytracer: bool = True) -> np.ndarray:
        """RGB picture (height, width, 3) of the current pose."""
        img = self.SC.renderer.RedrawAndGetImage(raytracer)
        return np.ascontiguousarray(img[..., :3])

    def solution(self, times: np.ndarray, poses: np.ndarray) -> dict:
        """The pose rows as an Exudyn solution dictionary (exudyn.utilities.LoadSolutionFile's format)."""
        data = np.column_stack([times, poses])
        n = poses.shape[1]
        return {"data": data, "columnsExported": [n, 0, 0, 0, 0, 0, 0], "nColumns": n, "nRows": len(times)}

    def view_interactive(self, times: np.ndarray, poses: np.ndarray, frame_period_s: float = 0.04) -> None:
        """Replay the poses in Exudyn's interactive viewer (needs a display)."""
        if not has_display():
            raise RenderError(
                "no display: the interactive viewer needs one (set DISPLAY or use gearbody render)"
            )
        self.SC.visualizationSettings.general.autoFitScene = False
        self.SC.renderer.Start()
        self.set_camera()
        self.mbs.SolutionViewer(
            self.solution(times, poses), timeout=frame_period_s, runOnStart=True, runMode=0
        )
        self.SC.renderer.Stop()


def has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
