"""A procedural motion library for offline use (no mocap files needed).

Every motion starts in the rest pose (T-pose at the origin), holds it for
``HOLD_SECONDS``, then blends into the movement over ``RAMP_SECONDS`` with a smooth
(C²) ramp, so a cloth simulation can settle first. Joint angles are smooth analytic
functions of time (no velocity spikes) and stay inside :data:`JOINT_LIMITS_DEG`.

Angles are built per joint as (x, y, z) degrees in the canonical world-aligned rest
axes (+X body left, −Y front, +Z up) and composed as ``R = Rz · Rx · Ry`` (the arm is
lowered about Y first, then swung about X). Signs used below: a negative X rotation
swings a hanging leg/arm forward; a positive X rotation bends the knee; +Y lowers the
left arm, −Y the right one; −Z bends the left elbow forward, +Z the right one.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from gnngarment.body.motion import Motion, MotionError
from gnngarment.body.skeleton import JOINT_INDEX, JOINT_NAMES, NUM_JOINTS

HOLD_SECONDS = 0.3
RAMP_SECONDS = 1.0
ARMS_DOWN_DEG = 72.0
THIGH_LENGTH = 0.39  # metres, Anny's default; used to keep feet on the floor
SHIN_LENGTH = 0.40

# Largest rotation angle (degrees) each joint reaches in the library (tested).
JOINT_LIMITS_DEG: dict[str, float] = {
    "pelvis": 360.0,  # body orientation: unbounded (spins)
    "L_hip": 120.0, "R_hip": 120.0,
    "spine1": 35.0, "spine2": 35.0, "spine3": 35.0,
    "L_knee": 140.0, "R_knee": 140.0,
    "L_ankle": 55.0, "R_ankle": 55.0,
    "L_foot": 30.0, "R_foot": 30.0,
    "neck": 60.0, "head": 60.0,
    "L_collar": 45.0, "R_collar": 45.0,
    "L_shoulder": 170.0, "R_shoulder": 170.0,
    "L_elbow": 145.0, "R_elbow": 145.0,
    "L_wrist": 70.0, "R_wrist": 70.0,
    "L_hand": 45.0, "R_hand": 45.0,
}  # fmt: skip


def smoothstep(x: np.ndarray) -> np.ndarray:
    """C² ramp from 0 (x ≤ 0) to 1 (x ≥ 1): 6x⁵ − 15x⁴ + 10x³."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * x * (x * (6.0 * x - 15.0) + 10.0)


def bump(x: np.ndarray) -> np.ndarray:
    """Smooth bump, 1 at x = 0, 0 for |x| ≥ 1 (C² : (1 − x²)³)."""
    return np.clip(1.0 - x * x, 0.0, None) ** 3


@dataclasses.dataclass
class _Builder:
    """Per-joint Euler angles (degrees) and root translation being assembled."""

    t: np.ndarray  # (T,) seconds since the ramp started (negative while holding)
    ease: np.ndarray  # (T,) 0 → 1 ramp
    fps: float
    angles: np.ndarray = dataclasses.field(init=False)
    translation: np.ndarray = dataclasses.field(init=False)

    def __post_init__(self) -> None:
        self.angles = np.zeros((len(self.t), NUM_JOINTS, 3))
        self.translation = np.zeros((len(self.t), 3))

    def add(self, joint: str, axis: int, degrees: np.ndarray | float) -> None:
        self.angles[:, JOINT_INDEX[joint], axis] += degrees

    def both(self, joint: str, axis: int, left: np.ndarray | float, right=None) -> None:
        """Left value, mirrored to the right side (Y and Z angles change sign)."""
        right = left if right is None else right
        self.add(f"L_{joint}", axis, left)
        self.add(f"R_{joint}", axis, right if axis == 0 else -np.asarray(right))

    def arms_down(self, degrees: float = ARMS_DOWN_DEG) -> None:
        self.both("shoulder", 1, degrees * self.ease)

    def legs(
        self, side: str, hip: np.ndarray, knee: np.ndarray, keep_foot_flat: bool = True
    ) -> None:
        """Hip flexion (forward, degrees) and knee flexion for one leg."""
        self.add(f"{side}_hip", 0, -hip)
        self.add(f"{side}_knee", 0, knee)
        if keep_foot_flat:
            self.add(f"{side}_ankle", 0, hip - knee)

    def crouch(self, hip: np.ndarray, knee: np.ndarray) -> None:
        """Both legs flexed alike, the pelvis lowered and shifted so the feet stay put."""
        for side in ("L", "R"):
            self.legs(side, hip, knee)
        h, k = np.radians(hip), np.radians(knee)
        self.translation[:, 2] -= THIGH_LENGTH * (1 - np.cos(h)) + SHIN_LENGTH * (1 - np.cos(h - k))
        self.translation[:, 1] += THIGH_LENGTH * np.sin(h) + SHIN_LENGTH * np.sin(h - k)

    def advance(self, speed: np.ndarray | float, axis: int = 1, sign: float = -1.0) -> None:
        """Integrate a forward speed (m/s, scaled by the ramp) into the translation."""
        velocity = np.broadcast_to(np.asarray(speed, dtype=np.float64), self.t.shape) * self.ease
        position = (
            np.concatenate([[0.0], np.cumsum(0.5 * (velocity[1:] + velocity[:-1]))]) / self.fps
        )
        self.translation[:, axis] += sign * position

    def motion(self, name: str) -> Motion:
        from scipy.spatial.transform import Rotation

        angles = self.angles.reshape(-1, 3)
        rotvec = Rotation.from_euler("yxz", angles[:, [1, 0, 2]], degrees=True).as_rotvec()
        rotations = rotvec.reshape(len(self.t), NUM_JOINTS, 3)
        # Large pelvis yaw (spins) is kept as a continuous rotation vector about +Z.
        yaw = self.angles[:, 0, 2]
        if np.allclose(self.angles[:, 0, :2], 0.0):
            rotations[:, 0] = np.stack([np.zeros_like(yaw), np.zeros_like(yaw), np.radians(yaw)], 1)
        return Motion(rotations, self.translation, self.fps, name)


# ---- the motions ------------------------------------------------------------------------
# Each takes (builder, speed, amplitude, rng) and fills the builder. ``speed`` scales the
# tempo, ``amplitude`` the joint angles; ``rng`` adds small seeded variations.


def _jitter(rng: np.random.Generator | None, spread: float = 0.1) -> float:
    return 1.0 if rng is None else float(rng.uniform(1.0 - spread, 1.0 + spread))


def _phase(rng: np.random.Generator | None) -> float:
    return 0.0 if rng is None else float(rng.uniform(-0.3, 0.3))


def _gait(b: _Builder, speed: float, amplitude: float, rng, run: bool) -> None:
    freq = (1.35 if run else 0.9) * speed * _jitter(rng, 0.05)
    phase = 2 * np.pi * freq * np.maximum(b.t, 0.0)
    e = b.ease
    a = amplitude * _jitter(rng)
    hip_amp, knee_amp = (38.0, 95.0) if run else (24.0, 55.0)
    for side, offset in (("L", 0.0), ("R", np.pi)):
        p = phase + offset
        hip = a * e * (hip_amp * np.sin(p) + (12.0 if run else 4.0))
        knee = a * e * (knee_amp * ((1 + np.cos(p - 0.3)) / 2) ** 2 + (15.0 if run else 5.0))
        b.legs(side, hip, knee, keep_foot_flat=False)
        b.add(f"{side}_ankle", 0, -a * e * 10.0 * np.sin(p + 0.8))
        swing = a * e * (30.0 if run else 18.0) * np.sin(p)
        b.add(f"{side}_shoulder", 0, swing)  # arms swing opposite to the legs
    b.arms_down(ARMS_DOWN_DEG - (10.0 if run else 0.0))
    b.both("elbow", 2, -a * e * (85.0 if run else 20.0))
    b.add("spine1", 0, -a * e * (10.0 if run else 3.0))  # lean forward
    b.add("pelvis", 2, a * e * 5.0 * np.sin(phase))
    b.add("spine2", 2, -a * e * 6.0 * np.sin(phase))
    b.translation[:, 2] += e * (0.04 if run else 0.015) * a * (np.cos(2 * phase) - 1) / 2
    step = (1.1 if run else 0.7) * a  # metres per step, two steps per cycle
    b.advance(2 * step * freq)


def _walk(b: _Builder, speed: float, amplitude: float, rng) -> None:
    _gait(b, speed, amplitude, rng, run=False)


def _run(b: _Builder, speed: float, amplitude: float, rng) -> None:
    _gait(b, speed, amplitude, rng, run=True)


def _cycle(b: _Builder, period: float) -> np.ndarray:
    """Phase in [0, 1) of a repeating cycle of ``period`` seconds (0 before the ramp)."""
    return np.mod(np.maximum(b.t, 0.0) / period, 1.0)


def _jump(b: _Builder, speed: float, amplitude: float, rng) -> None:
    a = amplitude * _jitter(rng)
    s = _cycle(b, 1.4 / speed)
    crouch = bump((s - 0.2) / 0.18) + bump((s - 0.8) / 0.18)  # before take-off, on landing
    air = bump((s - 0.5) / 0.22)
    e = b.ease
    b.crouch(a * e * 50.0 * crouch, a * e * 80.0 * crouch)
    height = 0.25 * a
    b.translation[:, 2] += e * height * air
    b.arms_down()
    b.both("shoulder", 0, a * e * (25.0 * crouch - 60.0 * air))  # swing back, then up
    b.add("spine1", 0, -a * e * 15.0 * crouch)
    b.both("ankle", 0, a * e * 20.0 * air)  # toes point in the air


def _squat(b: _Builder, speed: float, amplitude: float, rng) -> None:
    a = amplitude * _jitter(rng)
    depth = a * b.ease * (1 - np.cos(2 * np.pi * np.maximum(b.t, 0.0) * 0.4 * speed)) / 2
    b.crouch(95.0 * depth, 115.0 * depth)
    b.arms_down()
    b.both("shoulder", 0, -70.0 * depth)  # arms forward for balance
    b.add("spine1", 0, -20.0 * depth)
    b.add("spine2", 0, -10.0 * depth)


def _arm_raise(b: _Builder, speed: float, amplitude: float, rng) -> None:
    a = amplitude * _jitter(rng)
    lift = (1 - np.cos(2 * np.pi * np.maximum(b.t, 0.0) * 0.35 * speed)) / 2
    # From hanging (+72°) up through the T-pose to overhead (−75°), sideways.
    b.both("shoulder", 1, b.ease * (ARMS_DOWN_DEG - a * 147.0 * lift))
    b.both("collar", 1, -b.ease * a * 15.0 * lift)
    b.both("elbow", 2, -b.ease * 10.0)


def _wave(b: _Builder, speed: float, amplitude: float, rng) -> None:
    a = amplitude * _jitter(rng)
    e = b.ease
    b.add("L_shoulder", 1, ARMS_DOWN_DEG * e)
    b.add("R_shoulder", 1, -10.0 * e)  # right arm slightly above horizontal
    b.add("R_shoulder", 0, -15.0 * e)  # and a little forward
    swing = np.sin(2 * np.pi * 1.6 * speed * np.maximum(b.t, 0.0) + _phase(rng))
    b.add("R_elbow", 1, e * (95.0 + a * 30.0 * swing))  # forearm up, waving sideways
    b.add("R_wrist", 1, e * a * 15.0 * swing)
    b.add("head", 2, -e * 10.0)
    b.add("spine2", 1, e * 4.0)


def _twist(b: _Builder, speed: float, amplitude: float, rng) -> None:
    a = amplitude * _jitter(rng)
    e = b.ease
    w = np.sin(2 * np.pi * 0.45 * speed * np.maximum(b.t, 0.0) + _phase(rng))
    lag = np.sin(2 * np.pi * 0.45 * speed * np.maximum(b.t, 0.0) + _phase(rng) - 0.6)
    b.add("pelvis", 2, e * a * 25.0 * w)
    for joint in ("spine1", "spine2", "spine3"):
        b.add(joint, 2, e * a * 12.0 * w)
    b.add("head", 2, -e * a * 15.0 * w)
    left, right = ((1 + w) / 2) ** 2, ((1 - w) / 2) ** 2  # smooth one-sided weights
    b.legs("L", e * a * 8.0 * left, e * a * 14.0 * left)
    b.legs("R", e * a * 8.0 * right, e * a * 14.0 * right)
    b.arms_down(ARMS_DOWN_DEG - 12.0 * a * lag**2)  # arms fly out a little
    b.both("shoulder", 0, e * a * 20.0 * lag, -e * a * 20.0 * lag)
    b.both("elbow", 2, -e * 25.0)


def _kick(b: _Builder, speed: float, amplitude: float, rng) -> None:
    a = amplitude * _jitter(rng)
    e = b.ease
    s = _cycle(b, 1.6 / speed)
    chamber = bump((s - 0.35) / 0.3)  # knee up
    extend = bump((s - 0.5) / 0.2)  # leg snaps out
    b.legs(
        "R", a * e * (70.0 * chamber), a * e * (90.0 * chamber * (1 - extend) + 10 * chamber), False
    )
    b.add("R_ankle", 0, a * e * 25.0 * extend)
    b.legs("L", e * 8.0 * chamber, e * 15.0 * chamber)  # support knee gives a little
    b.add("spine1", 0, a * e * 10.0 * chamber)  # lean back for balance
    b.arms_down(ARMS_DOWN_DEG - 25.0)
    b.both("shoulder", 0, -a * e * 20.0 * chamber, a * e * 20.0 * chamber)
    b.both("elbow", 2, -e * 60.0)


def _sit_down(b: _Builder, speed: float, amplitude: float, rng) -> None:
    a = amplitude * _jitter(rng, 0.05)
    # Down, hold, up: one cycle, tempo by speed.
    s = np.maximum(b.t, 0.0) * speed
    down = smoothstep(s / 1.2) - smoothstep((s - 2.0) / 1.2)
    b.crouch(a * 90.0 * down, a * 95.0 * down)
    transition = np.abs(np.gradient(down, b.t)) * 1.2 / 1.9  # ≈1 at the fastest change
    b.add("spine1", 0, -25.0 * np.clip(transition, 0, 1) * a)  # lean forward to sit/stand
    b.arms_down()
    b.both("shoulder", 0, -30.0 * np.clip(transition, 0, 1) * a)
    b.both("elbow", 2, -b.ease * 20.0 - 40.0 * down)


def _dance(b: _Builder, speed: float, amplitude: float, rng) -> None:
    a = amplitude * _jitter(rng)
    e = b.ease
    tt = np.maximum(b.t, 0.0) * speed
    # A spin: one full turn every ~2.5 s, eased in; the yaw keeps growing (continuous).
    turn_rate = 360.0 / 2.5 * speed * a
    yaw = np.concatenate([[0.0], np.cumsum(0.5 * (e[1:] + e[:-1]))]) / b.fps * turn_rate
    b.add("pelvis", 2, yaw)
    beat = 2 * np.pi * 1.2 * tt
    left, right = ((1 + np.sin(beat)) / 2) ** 2, ((1 - np.sin(beat)) / 2) ** 2
    b.legs("L", e * 25.0 * a * left, e * 40.0 * a * left)
    b.legs("R", e * 25.0 * a * right, e * 40.0 * a * right)
    b.add("spine2", 1, e * 10.0 * a * np.sin(beat / 2))
    b.add("spine1", 1, e * 6.0 * a * np.sin(beat / 2))
    b.arms_down(ARMS_DOWN_DEG - 45.0 * a * (0.6 + 0.4 * np.sin(beat / 2)))
    b.both("elbow", 2, -e * a * (40.0 + 30.0 * np.sin(beat + _phase(rng))))
    b.add("head", 1, -e * 8.0 * a * np.sin(beat / 2))
    b.translation[:, 2] += e * 0.02 * a * (np.cos(2 * beat) - 1) / 2


#: Secondary movements layered onto every motion: (joint, axis, degrees at amplitude 1).
#: Real mocap moves the neck, head, collars, wrists and hands even while walking (a real
#: CLOTH3D walk turns neck, collars and head 18–26°); a library that never moves them
#: cannot teach a model that they do not move a pair of trousers. Each term is a slow
#: sine (0.25–0.35 Hz), so its first peak (≈20°) lands within the first second after the
#: rest hold, even in a 1.2 s clip. Axes: 0 nods / swings forward-back, 1 tilts sideways,
#: 2 turns about the vertical.
SECONDARY_MOTION_DEG: tuple[tuple[str, int, float], ...] = (
    ("neck", 2, 20.0), ("neck", 0, 18.0),
    ("head", 2, 20.0), ("head", 0, -18.0), ("head", 1, 12.0),
    ("spine1", 1, 12.0), ("spine2", 1, -12.0), ("spine2", 0, -8.0), ("spine3", 0, -12.0),
    ("spine3", 2, 10.0),
    ("L_collar", 1, -20.0), ("R_collar", 1, 20.0),
    ("L_wrist", 0, 25.0), ("R_wrist", 0, -25.0), ("L_wrist", 2, -15.0), ("R_wrist", 2, 15.0),
    ("L_hand", 0, 22.0), ("R_hand", 0, 22.0),
    ("L_ankle", 0, 12.0), ("R_ankle", 0, -12.0),
    ("L_foot", 0, 20.0), ("R_foot", 0, 20.0),
)


def _secondary_motion(b: _Builder, amplitude: float, rng: np.random.Generator | None) -> None:
    """Layer :data:`SECONDARY_MOTION_DEG` onto the motion in ``b`` (eased in like the
    motion itself; tempo, phase and size varied per term by ``rng``)."""
    t = np.maximum(b.t, 0.0)
    for k, (joint, axis, degrees) in enumerate(SECONDARY_MOTION_DEG):
        if rng is None:  # canonical: fixed, distinct tempi so the terms do not move in step
            freq, phase, size = 0.25 + 0.1 * ((k * 7) % 11) / 10, 0.0, 1.0
        else:
            freq, phase, size = (float(rng.uniform(0.25, 0.35)), float(rng.uniform(-0.3, 0.3)),
                                 float(rng.uniform(0.9, 1.1)))
        b.add(joint, axis, amplitude * size * degrees * b.ease
              * np.sin(2 * np.pi * freq * t + phase))


@dataclasses.dataclass(frozen=True)
class ProceduralMotion:
    """A named entry of the library."""

    name: str
    description: str
    build: Callable[..., None]


MOTION_LIBRARY: dict[str, ProceduralMotion] = {
    m.name: m
    for m in (
        ProceduralMotion("walk", "walk forward (−Y), ~1.3 m/s at speed 1, arms swinging", _walk),
        ProceduralMotion("run", "run forward (−Y), ~3 m/s at speed 1, elbows bent", _run),
        ProceduralMotion("jump", "jumps in place: crouch, take off ~25 cm, land", _jump),
        ProceduralMotion("squat", "deep squats, arms forward, feet planted", _squat),
        ProceduralMotion("arm_raise", "both arms raised sideways overhead and lowered", _arm_raise),
        ProceduralMotion("wave", "right hand waving above the shoulder", _wave),
        ProceduralMotion("twist", "torso and pelvis turn left and right, arms swinging", _twist),
        ProceduralMotion("kick", "right-leg front kicks, arms guarding", _kick),
        ProceduralMotion("sit_down", "sit down (no chair), hold, stand up", _sit_down),
        ProceduralMotion("dance", "stepping dance while spinning about the vertical axis", _dance),
    )
}


def list_motions() -> list[tuple[str, str]]:
    """(name, description) of every procedural motion."""
    return [(m.name, m.description) for m in MOTION_LIBRARY.values()]


def make_motion(
    name: str,
    duration: float = 4.0,
    fps: float = 30.0,
    speed: float = 1.0,
    amplitude: float = 1.0,
    seed: int | None = None,
) -> Motion:
    """A procedural motion from :data:`MOTION_LIBRARY`.

    Args:
        name: library name (see :func:`list_motions`).
        duration: seconds, including the rest hold and the ramp (> 0).
        fps: frames per second (> 0).
        speed: tempo multiplier in [0.25, 2].
        amplitude: joint-angle multiplier in [0, 1.2] (limits are tested at 1.2).
        seed: ``None`` for the canonical motion, else small seeded variations of
            amplitude, tempo and phase.

    Returns:
        A :class:`Motion` of ``round(duration · fps) + 1`` frames starting at rest.
    """
    if name not in MOTION_LIBRARY:
        raise MotionError(f"unknown motion '{name}'; available: {', '.join(MOTION_LIBRARY)}")
    if not np.isfinite(fps) or fps <= 0:
        raise MotionError(f"{name}: fps must be > 0, got {fps}")
    if not np.isfinite(duration) or duration <= 0:
        raise MotionError(f"{name}: duration must be > 0, got {duration}")
    if not 0.25 <= speed <= 2.0:
        raise MotionError(f"{name}: speed must be in [0.25, 2], got {speed}")
    if not 0.0 <= amplitude <= 1.2:
        raise MotionError(f"{name}: amplitude must be in [0, 1.2], got {amplitude}")
    count = round(duration * fps) + 1
    t = np.arange(count) / fps - HOLD_SECONDS
    builder = _Builder(t=t, ease=smoothstep(t / RAMP_SECONDS), fps=float(fps))
    rng = None if seed is None else np.random.default_rng(seed)
    MOTION_LIBRARY[name].build(builder, speed, amplitude, rng)
    _secondary_motion(builder, amplitude, rng)
    return builder.motion(name)


__all__ = [
    "JOINT_LIMITS_DEG",
    "JOINT_NAMES",
    "MOTION_LIBRARY",
    "ProceduralMotion",
    "list_motions",
    "make_motion",
]
