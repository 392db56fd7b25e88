"""Articulated walking pedestrians: tapered view-facing limbs on a skeleton with a walking gait.

Proportions follow the anthropometric canon (segment lengths and joint heights as fractions of
stature: hip 0.53, knee 0.285, ankle 0.039, shoulder 0.818, chin 0.87, upper arm 0.186, forearm
0.146, foot 0.152, shoulder width 0.259; Winter, *Biomechanics and Motor Control of Human Movement*,
fig. 4.1). Trunk widths and depths are those of a clothed adult (chest 0.18-0.23 h deep, from a shirt
to a padded jacket): a thinner side-view trunk makes crossing pedestrians much harder to recognise for a HOG
people detector (Dalal & Triggs 2005), as it would be for real people. The gait follows normative
sagittal joint angles over the cycle (hip, knee, shoe pitch: heel-off late in stance, toe up at heel
strike) with counter-swinging arms; the whole figure is then lowered or raised so that its lowest
shoe point rests on the ground (z = 0), which gives the pelvis its natural bob.

Limbs and trunk are flat tapered quads turned towards the viewer (the rig centre), so both cameras
see the same 3D geometry. Each is split lengthwise into a lit and a shadowed half (a cheap cylinder
shading under the renderer's sun); shoes are small boxes. Parts that touch at the same depth get a
few millimetres of bias towards the viewer so that the z-test orders them deterministically (arms
over trunk, shirt over trousers, face over hair), never by rounding noise.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .patches import SUN_DIR, box_faces
from .scene import ObjectState
from .vec3 import UP, Vec3, add, cross, dot, madd, mul, norm, sub, vec

# BGR colours. Clothing keeps some luminance or hue contrast against the grey asphalt (~100, 97, 95).
SHIRTS = [(40, 40, 175), (95, 45, 20), (35, 90, 30), (28, 28, 30), (225, 225, 222), (205, 140, 80),
          (115, 40, 110), (35, 115, 215), (30, 160, 210), (45, 30, 125), (125, 115, 25), (150, 100, 210),
          (55, 55, 60), (90, 130, 160), (30, 70, 150), (140, 70, 40)]
PANTS = [(120, 75, 40), (85, 55, 35), (30, 30, 32), (70, 105, 135), (50, 50, 55), (40, 60, 95),
         (75, 45, 30), (115, 75, 45)]
SKINS = [(150, 180, 225), (125, 160, 210), (95, 130, 185), (70, 100, 150), (50, 70, 105)]
HAIR = [(20, 20, 25), (25, 40, 65), (45, 75, 120), (80, 150, 190), (150, 150, 155), (30, 30, 90)]
SHOES = [(25, 25, 28), (30, 50, 80), (215, 215, 215), (40, 40, 40)]

SUN = vec(SUN_DIR)
"""Light direction (world) for the lit/shadowed halves: the renderer's sun."""

# Normal walking over one gait cycle (fraction 0 = heel strike of that leg), degrees; after Winter's
# normative sagittal kinematics. HIP: thigh forwards of the vertical; KNEE: flexion; FOOT: shoe pitch
# relative to the ground, toe down positive (heel-off late in stance, toe up at heel strike). The swing is on the
# low side of normal (knee peak 51 deg, not the mean ~60, as at slower speeds: Koopman et al., J. Biomech. 47, 2014;
# hip back near neutral at toe-off): with the mean curve the trailing shank kicks far back after toe-off, the pose
# the photo-trained INRIA people detector missed most on crossing frames (tools/inria_look.py).
GAIT_C = np.linspace(0.0, 1.0, 11)
HIP = np.array([22.0, 19.0, 12.0, 5.0, -2.0, -9.0, -1.0, 12.0, 22.0, 25.0, 22.0])
KNEE = np.array([2.0, 10.0, 15.0, 10.0, 8.0, 22.0, 36.0, 51.0, 38.0, 13.0, 2.0])
FOOT = np.array([-10.0, 0.0, 0.0, 0.0, 5.0, 14.0, 34.0, 25.0, 5.0, -8.0, -10.0])


class _Figure:
    """Collects one pedestrian's patches, then drops them all so that the lowest point is at z = 0."""

    def __init__(self, view: Vec3, oid: int):
        self.view = view
        self.oid = oid
        self.rows: list[tuple] = []  # (origin, e1, e2, colour, outline, box-or-None)

    def _toward_view(self, p: Vec3, bias: float) -> Vec3:
        # p + bias d / |d|, d the horizontal direction from p to the viewer
        if bias == 0.0:
            return p
        d = (self.view[0] - p[0], self.view[1] - p[1], 0.0)
        n = norm(d) + 1e-12
        return (p[0] + bias * d[0] / n, p[1] + bias * d[1] / n, p[2] + bias * d[2] / n)

    def limb(self, p0, p1, r0: float, r1: float, color, bias: float = 0.0, caps: tuple = (True, True)) -> None:
        """A tapered view-facing quad from p0 (half-width r0) to p1 (half-width r1) with round caps.

        Each half (either side of the axis) is a rectangle plus a parallelogram for the taper; the half
        facing the sun is a little brighter than the other.
        """
        p0 = self._toward_view(p0, bias)
        p1 = self._toward_view(p1, bias)
        axis = sub(p1, p0)
        side = cross(axis, sub(self.view, ((p0[0] + p1[0]) / 2, (p0[1] + p1[1]) / 2, (p0[2] + p1[2]) / 2)))
        n = norm(side)
        if n < 1e-9:
            return
        side = (side[0] / n, side[1] / n, side[2] / n)
        if r0 < r1:  # build from the wide end
            p0, p1, r0, r1, axis, caps = p1, p0, r1, r0, (-axis[0], -axis[1], -axis[2]), caps[::-1]
        if r0 > 1.9 * r1:  # too steep a taper for one rectangle + parallelogram per half: split it
            rm = r0 / 1.8
            pm = madd(p0, (r0 - rm) / (r0 - r1), axis)
            self.limb(p0, pm, r0, rm, color, caps=(caps[0], False))
            self.limb(pm, p1, rm, r1, color, caps=(False, caps[1]))
            return
        sun = dot(side, SUN)
        lit = 1.0 if sun >= 0 else -1.0
        for sgn in (lit, -lit):
            s = mul(sgn, side)
            k = 1.0 + (0.13 * abs(sun) + 0.04) * (1 if sgn == lit else -1)
            col = tuple(min(255.0, c * k) for c in color)
            # the lit half overlaps the centre line by a little and sits 2 mm nearer, so it wins there
            over, nb = (0.15 * r1, 0.002) if sgn == lit else (0.0, 0.0)
            near = self._toward_view(p0, nb)
            self.rows.append((madd(near, -over, s), mul(r1 + over, s), axis, col, 0, None))
            if r0 - r1 > 1e-6:
                w = min(r0 - r1 + 0.1 * r1, r1)
                e2 = madd(axis, r1 - r0, s)
                self.rows.append((madd(near, r0, s), mul(-w, s), e2, col, 0, None))
        for p, r, c in ((p0, r0, caps[0]), (p1, r1, caps[1])):
            if c:
                self.disc(p, r, r, color)

    def disc(self, c, ry: float, rx: float, color, bias: float = 0.0) -> None:
        """A view-facing ellipse centred at c: half-height ry, half-width rx."""
        c = self._toward_view(c, bias)
        d = sub(self.view, c)
        n = norm(d) + 1e-12
        d = (d[0] / n, d[1] / n, d[2] / n)
        right = cross(UP, d)
        n = norm(right) + 1e-12
        right = (right[0] / n, right[1] / n, right[2] / n)
        upv = cross(d, right)
        self.rows.append((madd(madd(c, -rx, right), -ry, upv), mul(2 * rx, right), mul(2 * ry, upv), tuple(color),
                          1, None))

    def box(self, center: Vec3, axes: tuple[Vec3, Vec3, Vec3], size: Vec3, color) -> None:
        """A box with its bottom (as PatchBuilder.box makes it): ``center``, ``axes`` (unit x, y, z of the box),
        ``size`` along them [m]."""
        self.rows.append((center, axes, size, color, -1, "box"))

    def lowest_z(self) -> float:
        """Lowest z [m] of everything collected so far."""
        z = math.inf
        for o, e1, e2, _, outline, kind in self.rows:
            if kind == "box":
                # the centre less the half extents' heights along each axis
                z = min(z, o[2] - (abs(e2[0] / 2 * e1[0][2]) + abs(e2[1] / 2 * e1[1][2]) + abs(e2[2] / 2 * e1[2][2])))
            elif outline == 1:
                z = min(z, o[2] + 0.5 * (e1[2] + e2[2]) - 0.5 * math.hypot(e1[2], e2[2]))
            else:
                z = min(z, o[2] + min(0.0, e1[2]) + min(0.0, e2[2]))
        return z

    def packed(self) -> np.ndarray:
        """The patches lowered onto the ground, packed as ``PatchBatch.pack`` packs them: (P, 19) float64."""
        dz = -self.lowest_z()
        rows = []
        for o, e1, e2, color, outline, kind in self.rows:
            if kind == "box":
                # one-sided, shaded, untextured faces, outwards as PatchBuilder.box orients them
                rows += [(*f, *a, *b, *color, -1, 0, self.oid, 0, 1, 1, 1)
                         for f, a, b in box_faces((o[0] + 0.0, o[1] + 0.0, o[2] + dz), e1, e2)]
            else:
                # two-sided, shaded, untextured (-1), repeat (1, 1)
                rows.append((o[0] + 0.0, o[1] + 0.0, o[2] + dz, *e1, *e2, *color, -1, outline, self.oid, 1, 1, 1, 1))
        return np.array(rows, dtype=np.float64)


def _turn(a: float, u: Vec3, b: float, v: Vec3) -> Vec3:
    """a u + b v."""
    return (a * u[0] + b * v[0], a * u[1] + b * v[1], a * u[2] + b * v[2])


@functools.lru_cache(maxsize=256)
def _style(style: int) -> tuple:
    """A figure's look drawn from its style seed, in a fixed order: shirt, trousers, skin, hair and shoe
    colours (BGR), build, long sleeves, shorts, long hair, bulk (see ``_Body``)."""
    rng = np.random.default_rng(style & 0xFFFFFFFF)
    colours = tuple(palette[int(rng.integers(len(palette)))] for palette in (SHIRTS, PANTS, SKINS, HAIR, SHOES))
    build = float(rng.uniform(0.92, 1.12))
    flags = tuple(bool(rng.random() < q) for q in (0.5, 0.12, 0.3))
    return (*colours, build, *flags, float(rng.uniform(1.0, 1.3)))


def _scaled(color, k: float) -> tuple:
    return tuple(min(255.0, c * k) for c in color)


class _Body:
    """One pedestrian's frame, style and how it is seen: stature ``h`` [m]; ``fwd``, ``left`` (3,) unit vectors
    of the walking direction at ``base`` (the pose on the ground) [world]; ``vdir`` the horizontal direction to
    the viewer; ``cf`` = 1 seen from the front or back, 0 from the side (``cs`` the other way); the gait cycle
    fraction ``c`` of the left leg (0 = heel strike). ``obj.style`` seeds the colours (BGR), build (a width
    factor), sleeves, shorts, long hair and bulk (upper-body clothing, from a shirt to a padded jacket; the
    hips get half of it), drawn in a fixed order so that a seed always dresses the same figure."""

    def __init__(self, obj: ObjectState, view: Vec3):
        (self.shirt, self.pants, self.skin, self.hair, self.shoes, self.build, self.long_sleeves, self.shorts,
         self.long_hair, self.bulk) = _style(int(obj.style))
        self.hips = 1.0 + 0.5 * (self.bulk - 1.0)
        p = obj.pose
        self.h = obj.height_m
        self.fwd = (math.cos(p.yaw_rad), math.sin(p.yaw_rad), 0.0)
        self.left = (-self.fwd[1], self.fwd[0], 0.0)
        self.base = (float(p.x_m), float(p.y_m), 0.0)
        self.walking = obj.speed_mps > 0.05
        self.c = (obj.gait_phase / (2 * math.pi)) % 1.0
        vdir = (view[0] - self.base[0], view[1] - self.base[1], 0.0)
        n = norm(vdir) + 1e-12
        self.vdir = (vdir[0] / n, vdir[1] / n, vdir[2] / n)
        self.cf = abs(dot(self.vdir, self.fwd))
        self.cs = math.sqrt(max(0.0, 1.0 - self.cf * self.cf))
        self.lean = 0.06 if self.walking else 0.0  # trunk leans forwards a little when walking [rad]

    @property
    def sides(self) -> tuple:
        """(side, gait cycle fraction) of the left (+1) and right (-1) limbs: half a cycle apart."""
        return (+1, self.c), (-1, (self.c + 0.5) % 1.0)

    def pt(self, x, y, z) -> Vec3:
        """The world point x forwards, y left, z up [m] of the figure's base."""
        return madd(madd(madd(self.base, x, self.fwd), y, self.left), z, UP)

    def seg(self, ang) -> Vec3:
        """Unit vector at angle ``ang`` from straight down, rotated forwards (sagittal plane)."""
        return _turn(math.sin(ang), self.fwd, -math.cos(ang), UP)

    def across(self, w, d, bk=None) -> float:
        """How wide a trunk part looks [m]: an elliptic cross-section of width w (across) and depth d (front to
        back), fractions of h; the clothing adds ``bk`` (default the upper body's bulk) to the depth."""
        bk = self.bulk if bk is None else bk
        return math.hypot(w * self.cf, d * self.cs * bk) * self.h * self.build

    def trunk(self, z, x=0.0) -> Vec3:
        """A point on the trunk's mid-line at height z [fraction of h], leaning forwards about the hips."""
        h = self.h
        return self.pt(x * h + (z - 0.53) * h * math.sin(self.lean), 0.0, z * h)


def _legs(fig: _Figure, body: _Body) -> None:
    """Thigh, shank (trousers, or shorts and skin) and a shoe pitched by the gait, per leg."""
    h, fwd, left, seg, build = body.h, body.fwd, body.left, body.seg, body.build
    hip_z, thigh, shank = 0.53 * h, 0.245 * h, 0.246 * h
    foot_l, ankle_h = 0.155 * h, 0.039 * h
    for sgn, cl in body.sides:
        if body.walking:
            a, knee_flex, toe_down = (math.radians(float(np.interp(cl, GAIT_C, t))) for t in (HIP, KNEE, FOOT))
            stance_y = 0.05 * h
        else:
            a, knee_flex, toe_down, stance_y = 0.02 * sgn, 0.03, 0.0, 0.055 * h
        b_ang = a - knee_flex
        hip = body.pt(0.0, sgn * stance_y, hip_z)
        knee = madd(hip, thigh, seg(a))
        ankle = madd(knee, shank, seg(b_ang))
        if body.shorts:
            mid = madd(hip, 0.55 * thigh, seg(a))
            fig.limb(hip, mid, 0.05 * h * build, 0.043 * h * build, body.pants, bias=0.005)
            fig.limb(mid, knee, 0.036 * h * build, 0.03 * h * build, body.skin, bias=0.004, caps=(False, True))
            fig.limb(knee, ankle, 0.033 * h * build, 0.02 * h * build, body.skin, bias=0.005)
        else:
            fig.limb(hip, knee, 0.05 * h * build, 0.034 * h * build, body.pants, bias=0.005)
            fig.limb(knee, ankle, 0.035 * h * build, 0.026 * h * build, body.pants, bias=0.005)
        # the shoe, pitched toe-down at heel-off and toe-up at heel strike
        f_dir = _turn(math.cos(toe_down), fwd, -math.sin(toe_down), UP)
        f_up = _turn(math.sin(toe_down), fwd, math.cos(toe_down), UP)
        shoe_h = 0.06 * h
        centre = madd(madd(ankle, 0.28 * foot_l, f_dir), shoe_h / 2 - ankle_h, f_up)
        fig.box(centre, (f_dir, left, f_up), (foot_l, 0.058 * h * build, shoe_h), body.shoes)


def _trunk(fig: _Figure, body: _Body) -> None:
    """Pelvis (trousers), torso (shirt) with a lighter chest, shoulders sloping to the neck."""
    trunk, across, hips, shirt = body.trunk, body.across, body.hips, body.shirt
    fig.limb(trunk(0.465, -0.004), trunk(0.6), across(0.098, 0.086, hips), across(0.086, 0.079, hips),
             body.pants, caps=(False, False))
    fig.limb(trunk(0.54), trunk(0.67, 0.006), across(0.09, 0.082, hips), across(0.086, 0.082, hips),
             _scaled(shirt, 0.95), bias=0.01, caps=(False, False))
    fig.limb(trunk(0.665, 0.006), trunk(0.785, 0.004), across(0.087, 0.084), across(0.104, 0.09),
             shirt, bias=0.01, caps=(False, False))
    fig.limb(trunk(0.78, 0.004), trunk(0.845), across(0.125, 0.086), across(0.055, 0.058),
             shirt, bias=0.011, caps=(False, False))


def _head(fig: _Figure, body: _Body) -> None:
    """Neck and head: face, hair cap, hair at the back, eyes when seen from the front, long hair."""
    h, fwd, left, cf, cs = body.h, body.fwd, body.left, body.cf, body.cs
    skin, hair = body.skin, body.hair
    fig.limb(body.trunk(0.82, 0.005), body.trunk(0.885, 0.01), 0.028 * h, 0.028 * h, _scaled(skin, 0.9),
             bias=0.0, caps=(False, False))
    head_c = body.trunk(0.935, 0.012)
    head_w = (0.048 * cf + 0.055 * cs) * h
    front = dot(body.vdir, fwd)
    face_bias, hair_bias = (0.02, 0.015) if front > -0.3 else (0.012, 0.02)
    fig.disc(head_c, 0.065 * h, head_w, skin, bias=face_bias)
    fig.disc(madd(madd(head_c, 0.022 * h, UP), -0.012 * h, fwd), 0.046 * h, head_w * 1.08, hair, bias=hair_bias)
    fig.disc(madd(madd(head_c, 0.006 * h, UP), -0.02 * h, fwd), 0.058 * h, head_w * 1.02, hair,
             bias=hair_bias - 0.004)
    if front > -0.2:  # eyes on the front of the head; hidden by the face or hair from behind
        for s in (+1, -1):
            eye = madd(madd(madd(head_c, 0.046 * h, fwd), 0.018 * h * s, left), 0.004 * h, UP)
            fig.disc(eye, 0.0055 * h, 0.008 * h, (40, 35, 35), bias=0.01)
    if body.long_hair:
        fig.limb(madd(head_c, -0.025 * h, fwd), madd(madd(head_c, -0.03 * h, fwd), -0.13 * h, UP), 0.05 * h,
                 0.045 * h, hair, bias=0.012 * cs, caps=(True, False))


def _arms(fig: _Figure, body: _Body) -> None:
    """Arms swinging against the legs: upper arm (sleeve), forearm (sleeve or skin), hand."""
    h, left, seg = body.h, body.left, body.seg
    build, hips, skin = body.build, body.hips, body.skin
    sleeve = _scaled(body.shirt, 0.93)
    for sgn, cl in body.sides:
        if body.walking:
            hip_a = math.radians(float(np.interp(cl, GAIT_C, HIP)))
            a = -0.8 * (hip_a - math.radians(9.0))
            a2 = a + 0.3 + 0.8 * max(0.0, a)
        else:
            a, a2 = 0.0, 0.12
        sh = madd(body.trunk(0.795), sgn * 0.113 * h * build, left)
        out = mul(0.07 * sgn, left)  # slight abduction so that the arm hangs clear of the waist
        elbow = madd(sh, 0.186 * h, add(seg(a), out))
        wrist = madd(elbow, 0.146 * h, madd(seg(a2), 0.5, out))
        fore = sleeve if body.long_sleeves else skin
        fig.limb(sh, elbow, 0.035 * h * build * hips, 0.028 * h * build * hips, sleeve, bias=0.025)
        fig.limb(elbow, wrist, 0.028 * h * build * hips, 0.021 * h * build, fore, bias=0.025, caps=(False, True))
        fig.disc(madd(wrist, 0.045 * h, seg(a2)), 0.042 * h, 0.024 * h, skin, bias=0.03)


def pedestrian_packed(obj: ObjectState, view_world) -> np.ndarray:
    """One pedestrian seen from ``view_world`` (3,) [m, world frame]: its patches packed as ``PatchBatch.pack``
    packs them, (P, 19). The pose's yaw is the walking (facing) direction; ``obj.height_m`` its stature;
    ``obj.style`` seeds clothing, skin, hair and build; ``obj.gait_phase`` [rad] the walking cycle (0 = left heel
    strike), used when ``obj.speed_mps`` > 0.05. The lowest shoe point touches the ground (z = 0) at the pose
    position; every patch carries ``obj.obj_id``."""
    view = vec(view_world)
    body = _Body(obj, view)
    fig = _Figure(view, obj.obj_id)
    # the patches in the order they have always been added (legs, trunk, head, arms): it is part of the output
    for part in (_legs, _trunk, _head, _arms):
        part(fig, body)
    return fig.packed()
