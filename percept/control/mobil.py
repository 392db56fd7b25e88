"""MOBIL on perceived neighbours: whether changing into the lane beside pays, and whether it is safe.

MOBIL ("Minimizing Overall Braking Induced by Lane changes", Kesting, Treiber & Helbing 2007) judges a change by
the Intelligent Driver Model's accelerations (IDM: Treiber, Hennecke & Helbing 2000) before and after it:
incentive  a~_c - a_c + p (a~_n - a_n + a~_o - a_o) > a_th (+ a bias towards the right lane, as an option),
safety     a~_n >= -b_safe,
with c the ego, n the new follower (behind in the target lane), o the old one (behind in the ego lane), a~ after
the change. highway-env's own traffic decides with the same model and these parameters (its ``IDMVehicle``).
Perception is not truth: every gap is taken ``sigmas`` standard deviations shorter and every closing speed that
much faster before the test, a lane with any track beside the ego (in the blind zone, seen by neither rig) is never
a target, and the gaps ahead and behind must each hold ``min_time_gap_s`` at the ego's speed. With no follower in
view in the target lane, one may still come from beyond the rear view: given ``unseen_speed_mps``, a follower at that
speed is assumed at the view's edge (``Neighbours.behind_m``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from percept.sensors import Neighbour, Neighbours, Zone

ACCEL_MPS2 = 3.0
"""IDM's maximum acceleration a [m/s²] (highway-env's COMFORT_ACC_MAX)."""
DECEL_MPS2 = 5.0
"""IDM's comfortable deceleration b [m/s²] (highway-env's -COMFORT_ACC_MIN)."""
TIME_GAP_S = 1.5
"""IDM's safe time headway T [s]."""
JAM_GAP_M = 5.0
"""IDM's bumper gap at a standstill s0 [m] (highway-env's DISTANCE_WANTED less a car's length)."""
DELTA = 4.0
"""IDM's acceleration exponent."""


def idm_accel(speed_mps: float, desired_mps: float, gap_m: float | None = None, closing_mps: float = 0.0) -> float:
    """IDM's acceleration [m/s²] of a car at ``speed_mps`` wanting ``desired_mps``, ``gap_m`` (bumper to bumper,
    None: a free road) behind a leader it closes on at ``closing_mps``."""
    v = max(speed_mps, 0.0)
    # a [1 - (v / v0)^delta - (s* / s)^2]
    free = 1.0 - (v / max(desired_mps, 0.1)) ** DELTA
    if gap_m is None:
        return ACCEL_MPS2 * free
    # s* = s0 + v T + v dv / (2 sqrt(a b))
    s_star = JAM_GAP_M + v * TIME_GAP_S + v * closing_mps / (2 * math.sqrt(ACCEL_MPS2 * DECEL_MPS2))
    return ACCEL_MPS2 * (free - (max(s_star, 0.0) / max(gap_m, 0.1)) ** 2)


@dataclass(frozen=True)
class MobilConfig:
    """MOBIL's parameters and the margins perception needs."""

    politeness: float = 0.0  # p: how much the followers' loss counts (highway-env's traffic: 0) [-]
    threshold_mps2: float = 0.2  # a_th: the least gain worth a change [m/s²]
    right_bias_mps2: float = 0.0  # a_bias: extra gain asked of a change to the left, given to one to the right [m/s²]
    safe_braking_mps2: float = 2.0  # b_safe: the most braking a change may impose on the new follower [m/s²]
    sigmas: float = 2.0  # gaps shortened, and closing speeds raised, by this many of their standard deviations [-]
    min_time_gap_s: float = 1.0  # each gap, ahead and behind in the target lane, at least this at the ego's speed [s]


@dataclass(frozen=True)
class Judgement:
    """MOBIL's verdict on one side."""

    side: int  # +1 left, -1 right
    gain_mps2: float  # the incentive's left-hand side less the bias (+ favours the change) [m/s²]
    imposed_mps2: float  # the new follower's acceleration after the change (pessimistic) [m/s²]
    reason: str  # "ok", or why not: "no lane", "new lane" (LaneChange's), "beside", "gap ahead", "gap behind",
    # "follower brakes", "unseen follower" (one assumed beyond the rear view would), "no gain"

    @property
    def go(self) -> bool:
        """The change pays and is safe."""
        return self.reason == "ok"

    @property
    def safe(self) -> bool:
        """The lane exists and the change is safe, whether or not it pays (a swerve needs no gain; a change under
        way that stops paying goes on)."""
        return self.reason in ("ok", "no gain")


def _gap(n: Neighbour, k: float) -> float:
    """A track's bumper gap, ``k`` of its sigmas shorter [m]."""
    return max(n.gap_m - k * n.sigma_x_m, 0.0)


def _closing(n: Neighbour, behind: bool, k: float) -> float:
    """How fast the gap to ``n`` closes [m/s], ``k`` sigmas faster: a car ahead closes as it is slower, one behind
    as it is faster."""
    return (n.rel_speed_mps if behind else -n.rel_speed_mps) + k * n.sigma_rel_speed_mps


def judge(side: int, lane_there: bool | None, neighbours: Neighbours, speed_mps: float, set_speed_mps: float,
          cfg: MobilConfig = MobilConfig(), unseen_speed_mps: float | None = None) -> Judgement:
    """MOBIL's verdict on changing into the lane on ``side`` (+1 left, -1 right), that ``lane_there`` says exists, for
    an ego at ``speed_mps`` wanting ``set_speed_mps`` among ``neighbours``; with no follower in view there, one at
    ``unseen_speed_mps`` [m/s] (None: no one) is assumed at the rear view's edge."""
    k, v = cfg.sigmas, speed_mps
    if lane_there is not True:
        return Judgement(side, 0.0, 0.0, "no lane")
    if neighbours.nearest(side, Zone.BESIDE) is not None:
        return Judgement(side, 0.0, 0.0, "beside")
    lead_new, follow_new = neighbours.nearest(side, Zone.AHEAD), neighbours.nearest(side, Zone.BEHIND)
    lead_old, follow_old = neighbours.nearest(0, Zone.AHEAD), neighbours.nearest(0, Zone.BEHIND)

    def ego_behind(lead: Neighbour | None) -> float:
        """The ego's acceleration behind ``lead`` (None: a free lane)."""
        return idm_accel(v, set_speed_mps) if lead is None else idm_accel(v, set_speed_mps, _gap(lead, k),
                                                                          _closing(lead, False, k))

    if lead_new is not None and _gap(lead_new, k) < cfg.min_time_gap_s * v:
        return Judgement(side, 0.0, 0.0, "gap ahead")
    if follow_new is not None and _gap(follow_new, k) < cfg.min_time_gap_s * (v + max(follow_new.rel_speed_mps, 0)):
        return Judgement(side, 0.0, 0.0, "gap behind")
    imposed = _behind_ego(follow_new, v, k)
    if follow_new is None and unseen_speed_mps is not None:
        # a car at v_u, behind_m back: a~_n = IDM(v_u, v_u, behind_m, v_u - v)
        imposed = idm_accel(unseen_speed_mps, unseen_speed_mps, neighbours.behind_m, unseen_speed_mps - v)
    if imposed < -cfg.safe_braking_mps2:
        return Judgement(side, 0.0, imposed, "follower brakes" if follow_new is not None else "unseen follower")
    # the new follower n goes from behind lead_new to behind the ego; the old one o from behind the ego to behind
    # lead_old
    polite = (imposed - _behind(follow_new, lead_new, v)) + (_behind(follow_old, lead_old, v)
                                                             - _behind_ego(follow_old, v, k))
    gain = ego_behind(lead_new) - ego_behind(lead_old) + cfg.politeness * polite
    # keep right: a change to the left must gain the bias more, one to the right gets it
    gain -= side * cfg.right_bias_mps2
    return Judgement(side, gain, imposed, "ok" if gain > cfg.threshold_mps2 else "no gain")


def _behind_ego(f: Neighbour | None, v: float, k: float) -> float:
    """The acceleration of ``f`` (None: no one, 0) following the ego at ``v`` [m/s], pessimistic by ``k`` sigmas;
    it is taken to want its own speed (a follower's wish is not seen)."""
    if f is None:
        return 0.0
    vf = v + f.rel_speed_mps
    return idm_accel(vf, vf, _gap(f, k), _closing(f, True, k))


def _behind(f: Neighbour | None, lead: Neighbour | None, v: float) -> float:
    """The acceleration of ``f`` (None: no one, 0) following ``lead`` (None: a free lane), both tracks around an ego
    at ``v`` [m/s]."""
    if f is None:
        return 0.0
    vf = v + f.rel_speed_mps
    if lead is None:
        return idm_accel(vf, vf)
    # bumper gap: x_lead - x_f less half of each length; closing: v_f - v_lead
    gap = lead.x_m - f.x_m - (lead.length_m + f.length_m) / 2
    return idm_accel(vf, vf, gap, f.rel_speed_mps - lead.rel_speed_mps)
