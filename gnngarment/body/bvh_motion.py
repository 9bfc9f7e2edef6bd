"""BVH motions onto the canonical skeleton: joint names, rest-pose retargeting, units.

A BVH file is read in three steps:

1. **Names** (:func:`map_bvh_joints`): each of the 24 canonical joints gets a BVH joint
   from :data:`BVH_JOINT_CANDIDATES` (CMU/cgspeed, CMU "LeftHip/LeftKnee/LeftAnkle",
   CMU's original ASF names ``lfemur/ltibia/upperback/thorax/lhumerus/lradius``, the
   Poser-style ``hip/abdomen/chest/lThigh/lShldr`` of most CMU conversions, Mixamo,
   MotionBuilder/HumanIK, 3ds Max Biped, Unreal, SMPL names), compared after
   :func:`normalize_joint_name` (namespace and ``mixamorig``/``Bip01`` prefixes dropped,
   case and punctuation ignored), or from a user joint map (:func:`read_joint_map`). A
   name that means two joints in different conventions (``LeftShoulder``: the collar
   in cgspeed/Mixamo, the upper arm in CMU's own naming; ``LeftFoot``: ankle or toes;
   ``LeftHand``: wrist or hand; ``Spine``) is decided by the hierarchy: it takes the
   upper joint only when a joint named for the lower one follows it in the tree.

   **Spine spread**: a file with fewer spine joints than our three lets one joint stand
   for several. Each spine joint it lacks joins the nearest mapped spine joint below
   it, and that joint's local rotation ``R`` (about its canonical parent) is shared
   equally: with ``k`` joints, each turns by ``R^(1/k)``, the same axis and ``1/k`` of
   the angle, so the top one ends exactly where the file's joint does and nothing above
   it changes. Poser-style ``abdomen/chest`` gives spine1 = abdomen and spine2 = spine3
   = ``chest^(1/2)``; a lone ``Spine`` under the neck gives spine1..spine3 a third each.
   A joint map's ``null`` keeps a joint out of the spread (at rest) and ends the run.
2. **Rest-pose retargeting**: the BVH rest pose (all channels zero) is often not our
   T-pose (CMU: arms down, legs splayed). For each limb joint ``j`` (hip, knee, ankle,
   shoulder, elbow, wrist) with mapped child ``c``, ``A_j`` is the shortest arc taking
   our T-pose bone ``J_c − J_j`` onto the BVH rest bone (global rest positions from the
   OFFSETs), and our global rotation is ``Q_j(t) = S_j(t) · G_k(t) · A_j``: ``G_k`` is
   the BVH global rotation of the joint that moves the bone (``j`` itself, or a
   zero-offset joint below it such as CMU's ``lhand``), ``S_j(t)`` the shortest arc that
   puts the bone exactly along the BVH's own ``c − j`` (the identity unless a rotating
   joint with an offset, a twist bone, sits between). The torso is not bent to match:
   both rests stand upright and their spine/neck/collar bone directions differ by
   anatomy (where each skeleton puts its joints), not by pose. The pelvis aligns a
   frame (pelvis→neck exactly, then the hips' left–right); spine, neck, head and
   collars use that frame, and leaves (toes, hands) their parent's ``A``. Local
   rotations are ``R_j = Q_parentᵀ Q_j``. So our body in the BVH's rest frame stands in
   the BVH's rest pose, and in every frame each limb bone points where the BVH's does.
3. **Units**: ``scale="auto"`` makes the recorded legs (hip→knee→ankle, mean of both
   sides; pose-independent bone lengths, and what foot placement depends on) as long as
   the target skeleton's; the root translation is scaled by it.

World frame: BVH is Y up, front +Z (CMU, Mixamo, MotionBuilder) and becomes Z up,
front −Y by ``C = Rx(+90°)``; a Z-up BVH (``up_axis="z"``, or detected from the rest
skeleton with ``"auto"``) is taken as is.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from gnngarment.body.motion import Motion, MotionError
from gnngarment.body.skeleton import JOINT_INDEX, JOINT_NAMES, JOINT_PARENTS, NUM_JOINTS

# Y-up, front +Z (BVH, SMPL) → Z-up, front −Y (canonical): a +90° rotation about X.
Y_UP_TO_CANONICAL = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])

# Rest joints (24, 3) of the canonical T-pose: Anny's default shape (AnnyBodyModel().rest()
# .joints, metres, rounded to 0.1 mm; tests/body/test_bvh_motion.py checks they agree).
# Only bone directions and the leg length are used, so a body-independent table suffices;
# pass ``rest_joints`` to retarget onto another body exactly.
DEFAULT_REST_JOINTS = np.array([
    [0.0, -0.0108, 0.0504], [0.1019, -0.0079, 0.0389], [-0.1019, -0.0079, 0.0389],
    [0.0, 0.0223, 0.1178], [0.1351, -0.0402, -0.3501], [-0.1351, -0.0402, -0.3501],
    [0.0, 0.0076, 0.2612], [0.1766, -0.0039, -0.7486], [-0.1766, -0.0039, -0.7486],
    [0.0, 0.0319, 0.3939], [0.1879, -0.1361, -0.7946], [-0.1879, -0.1361, -0.7946],
    [0.0, -0.0075, 0.5597], [0.0220, -0.0256, 0.4930], [-0.0220, -0.0256, 0.4930],
    [0.0, -0.0419, 0.6567], [0.1616, -0.0171, 0.4675], [-0.1616, -0.0171, 0.4675],
    [0.4141, -0.0171, 0.4675], [-0.4141, -0.0171, 0.4675], [0.6412, -0.0171, 0.4675],
    [-0.6412, -0.0171, 0.4675], [0.7375, -0.0171, 0.4675], [-0.7375, -0.0171, 0.4675],
])  # fmt: skip


class UnmappedJointsWarning(UserWarning):
    """Joints of a motion file that are not mapped onto the canonical skeleton."""


# Candidate BVH names per canonical joint, normalised (normalize_joint_name), in order of
# preference. "<side>" is left/right, "<s>" is l/r. Lists are written for the left side.
_LEFT_CANDIDATES: dict[str, tuple[str, ...]] = {
    "hip": ("<side>upleg", "<side>thigh", "<side>upperleg", "<s>upleg", "<s>thigh",
            "thigh<s>", "upperleg<s>", "<side>hip", "<s>hip", "<s>femur"),
    "knee": ("<side>leg", "<side>shin", "<side>knee", "<side>lowerleg", "<side>calf",
             "<s>leg", "<s>shin", "<s>knee", "<s>calf", "calf<s>", "lowerleg<s>", "shin<s>",
             "<s>tibia"),
    "ankle": ("<side>ankle", "<s>ankle", "ankle<s>", "<side>foot", "<s>foot", "foot<s>"),
    "foot": ("<side>toebase", "<side>toe", "<side>toes", "<side>ball", "<s>toebase", "<s>toe",
             "<s>toe0", "<s>toes", "ball<s>", "toe<s>", "<side>foot", "<s>foot"),
    "collar": ("<side>collar", "<side>clavicle", "<s>collar", "<s>clavicle", "clavicle<s>",
               "<side>shoulder", "<s>shoulder"),
    "shoulder": ("<side>arm", "<side>uparm", "<side>upperarm", "<s>uparm", "<s>upperarm",
                 "upperarm<s>", "<s>shldr", "<side>shoulder", "<s>shoulder", "<s>arm",
                 "<s>humerus"),
    "elbow": ("<side>forearm", "<side>lowarm", "<side>lowerarm", "<side>elbow", "<s>forearm",
              "<s>lowarm", "<s>lowerarm", "lowerarm<s>", "<s>elbow", "<s>radius"),
    "wrist": ("<side>wrist", "<s>wrist", "<side>hand", "<s>hand", "hand<s>"),
    "hand": ("<side>fingerbase", "<side>fingers", "<s>fingers", "<side>handmiddle1",
             "<side>handindex1", "<side>finger2", "<s>finger2", "middle01<s>",
             "<side>hand", "<s>hand"),
}  # fmt: skip


def _sided(templates: tuple[str, ...], side: str) -> tuple[str, ...]:
    long, short = ("left", "l") if side == "L" else ("right", "r")
    return tuple(t.replace("<side>", long).replace("<s>", short) for t in templates)


BVH_JOINT_CANDIDATES: dict[str, tuple[str, ...]] = {
    "pelvis": ("hips", "pelvis", "hip", "root"),
    "spine1": ("lowerback", "spine", "spine01", "abdomen", "spine1"),
    "spine2": ("spine", "spine1", "spine02", "chest", "spine2", "upperback"),
    "spine3": ("spine1", "spine2", "spine03", "chest2", "chest", "upperchest", "spine3", "thorax"),
    # CMU's upperneck before lowerneck: lowerneck sits on the thorax (offset 0), so the
    # whole neck bend folds into ours, as CMU 131's lowerneck folds into its Neck.
    "neck": ("neck", "neck01", "upperneck", "lowerneck"),
    "head": ("head",),
    **{
        f"{side}_{part}": _sided(templates, side)
        for side in ("L", "R")
        for part, templates in _LEFT_CANDIDATES.items()
    },
}
BVH_JOINT_CANDIDATES = {name: BVH_JOINT_CANDIDATES[name] for name in JOINT_NAMES}

# Joints a BVH may lack (with a warning: left at rest, or spine2/spine3 share the rotation of
# the spine joint below, see _spine_runs); any other missing joint is an error.
BVH_OPTIONAL_JOINTS = frozenset(
    {"spine2", "spine3", "neck", "L_collar", "R_collar", "L_foot", "R_foot", "L_hand", "R_hand"}
)

# The canonical child whose bone each joint's rotation aims (None: a leaf); a limb joint's
# rest bone runs to the nearest mapped joint down this chain.
_PRIMARY_CHILD: dict[str, str | None] = {
    "pelvis": None, "spine1": "spine2", "spine2": "spine3", "spine3": "neck", "neck": "head",
    "head": None,
    **{f"{s}_{a}": (f"{s}_{b}" if b else None) for s in "LR" for a, b in (
        ("hip", "knee"), ("knee", "ankle"), ("ankle", "foot"), ("foot", None),
        ("collar", "shoulder"), ("shoulder", "elbow"), ("elbow", "wrist"),
        ("wrist", "hand"), ("hand", None))},
}  # fmt: skip
# Joints whose rest bone is aligned to the BVH's (the limbs: where rest poses differ).
_LIMB_JOINTS = frozenset(
    f"{s}_{part}" for s in "LR" for part in ("hip", "knee", "ankle", "shoulder", "elbow", "wrist")
)
_CHILDREN = {j: [c for c in range(NUM_JOINTS) if JOINT_PARENTS[c] == j] for j in range(NUM_JOINTS)}


def normalize_joint_name(name: str) -> str:
    """A BVH joint name for table look-up: the part after any ``namespace:`` or ``a|b``,
    lower case, letters and digits only, without a ``mixamorig``/``bip01`` prefix.

    ``"mixamorig:LeftUpLeg"`` → ``"leftupleg"``, ``"Bip01 L Thigh"`` → ``"lthigh"``.
    """
    bare = re.split(r"[:|]", name)[-1].lower()
    bare = re.sub(r"[^a-z0-9]", "", bare)
    return re.sub(r"^(mixamorig\d*|bip0*1)", "", bare) or bare


def read_joint_map(path: str | Path) -> dict[str, str | None]:
    """A user joint map: a ``.json`` or ``.yaml`` mapping of canonical joint names
    (:data:`~gnngarment.body.skeleton.JOINT_NAMES`) to the file's joint names, e.g.
    ``{"L_hip": "Thigh_L", "L_knee": "Calf_L"}``; ``null`` leaves an optional joint at
    rest. Joints not listed are found by the name table.

    Raises:
        MotionError: unreadable file, not a mapping, unknown canonical name, or a value
            that is not a string/null; the message names the file and the key.
    """
    path = Path(path)
    if not path.is_file():
        raise MotionError(f"{path}: joint map file not found")
    from gnngarment.config import MAPPING_SUFFIXES, ConfigError, parse_mapping_text

    if path.suffix.lower() not in MAPPING_SUFFIXES:
        raise MotionError(f"{path}: joint map must be a .json, .yaml or .yml file")
    text = path.read_text(errors="replace")
    try:
        values = parse_mapping_text(text, path.suffix, str(path))
    except ConfigError as error:  # names the file already
        raise MotionError(str(error)) from None
    except Exception as error:  # json syntax errors
        message = " ".join(str(error).split())
        raise MotionError(f"{path}: not a readable joint map ({message})") from error
    return _check_joint_map(values, str(path))


def _check_joint_map(values: object, source: str) -> dict[str, str | None]:
    if not isinstance(values, Mapping):
        raise MotionError(
            f"{source}: a joint map must be a mapping of canonical joint names to the "
            f"file's joint names, got {type(values).__name__}"
        )
    checked: dict[str, str | None] = {}
    for key, value in values.items():
        if key not in JOINT_INDEX:
            raise MotionError(
                f"{source}: joint map key '{key}' is not a canonical joint "
                f"(expected some of {', '.join(JOINT_NAMES)})"
            )
        if value is not None and not isinstance(value, str):
            raise MotionError(
                f"{source}: joint map value of '{key}' must be a joint name or null, got {value!r}"
            )
        if value is None and key not in BVH_OPTIONAL_JOINTS:
            raise MotionError(
                f"{source}: joint map sets '{key}' to null, but that joint is required "
                f"(only {', '.join(sorted(BVH_OPTIONAL_JOINTS))} may be left at rest)"
            )
        checked[str(key)] = value
    return checked


def map_bvh_joints(
    names: list[str],
    parents: list[int],
    joint_map: Mapping[str, str | None] | str | Path | None = None,
    source: str = "",
) -> dict[str, str]:
    """Which BVH joint plays each canonical joint.

    Args:
        names: the BVH joint names, parents before children.
        parents: index of each joint's parent in ``names`` (−1 for the root).
        joint_map: a user joint map (a mapping, or a file for :func:`read_joint_map`);
            its entries are taken first, the rest comes from the name table.
        source: the motion file, for messages.

    Returns:
        canonical joint name → BVH joint name, for every mapped canonical joint (the
        required ones always; optional ones when found).

    Raises:
        MotionError: a required joint is not found, a joint-map name is not in the file,
            or the mapped joints do not form the canonical tree (e.g. a knee mapped
            outside its leg).
    """
    return _choose_bvh_joints(names, parents, joint_map, source)[0]


def _choose_bvh_joints(
    names: list[str],
    parents: list[int],
    joint_map: Mapping[str, str | None] | str | Path | None,
    source: str,
) -> tuple[dict[str, str], frozenset[str]]:
    """:func:`map_bvh_joints`'s mapping, and the canonical joints the user's joint map
    sets to ``null`` (held at rest, never given a share of another joint's rotation)."""
    where = f"{source}: " if source else ""
    map_source = source
    if isinstance(joint_map, (str, Path)):
        map_source = str(joint_map)
        joint_map = read_joint_map(joint_map)
    elif joint_map is not None:
        joint_map = _check_joint_map(joint_map, source or "joint map")
    index = {name: i for i, name in enumerate(names)}
    normalized: dict[str, list[int]] = {}
    for i, name in enumerate(names):
        normalized.setdefault(normalize_joint_name(name), []).append(i)
    ancestors: list[set[int]] = []
    for i, parent in enumerate(parents):
        if parent >= i:
            raise MotionError(f"{where}BVH joints are not listed parents first")
        ancestors.append(set() if parent < 0 else ancestors[parent] | {parent})

    chosen: dict[int, int] = {}  # canonical joint → BVH joint index
    excluded: set[int] = set()
    user_keys = set(joint_map or {})
    for key, value in (joint_map or {}).items():
        j = JOINT_INDEX[key]
        if value is None:
            excluded.add(j)
            continue
        if value not in index:
            raise MotionError(
                f"{map_source}: joint map '{key}' → '{value}': no joint '{value}' in "
                f"{source or 'the motion'} (its joints: {', '.join(names)})"
            )
        if index[value] in chosen.values():
            raise MotionError(f"{map_source}: joint map uses '{value}' for two joints")
        chosen[j] = index[value]

    def mapped_ancestor(j: int) -> int | None:
        parent = JOINT_PARENTS[j]
        while parent >= 0 and parent not in chosen:
            parent = JOINT_PARENTS[parent]
        return chosen.get(parent) if parent >= 0 else None

    def below(j: int) -> set[int]:  # canonical descendants of j
        out: set[int] = set()
        stack = list(_CHILDREN[j])
        while stack:
            c = stack.pop()
            out.add(c)
            stack.extend(_CHILDREN[c])
        return out

    def fits(j: int, b: int) -> bool:
        """BVH joint b may play canonical joint j: below j's mapped ancestor, above the
        joints already chosen for j's descendants."""
        if b in chosen.values():
            return False
        top = mapped_ancestor(j)
        if top is not None and top not in ancestors[b]:
            return False
        # (Joints the user mapped are checked with the tree below, naming the map.)
        return all(
            b in ancestors[chosen[d]]
            for d in below(j)
            if d in chosen and JOINT_NAMES[d] not in user_keys
        )

    def ambiguous_ok(j: int, name: str, b: int) -> bool:
        """A name that also fits another canonical joint (LeftShoulder: collar or upper
        arm; LeftFoot: ankle or toes; Spine1) is taken in the first pass only when the
        hierarchy settles it: for a joint j above that other joint d, a BVH joint named
        for d by another of its names lies below b; never while a canonical ancestor that
        could take the name is still unmapped."""
        ancestor = JOINT_PARENTS[j]
        while ancestor >= 0:
            if ancestor not in chosen and name in BVH_JOINT_CANDIDATES[JOINT_NAMES[ancestor]]:
                return False
            ancestor = JOINT_PARENTS[ancestor]
        for d in below(j):
            if name not in BVH_JOINT_CANDIDATES[JOINT_NAMES[d]]:
                continue
            others = [n for n in BVH_JOINT_CANDIDATES[JOINT_NAMES[d]] if n != name]
            if not any(b in ancestors[k] for n in others for k in normalized.get(n, ())):
                return False
        return True

    for strict in (True, False):
        for j, joint in enumerate(JOINT_NAMES):
            if j in chosen or j in excluded:
                continue
            if not strict and joint in BVH_OPTIONAL_JOINTS:
                continue  # an ambiguous name is never taken for an optional joint
            for candidate in BVH_JOINT_CANDIDATES[joint]:
                picks = [
                    b for b in normalized.get(candidate, ())
                    if fits(j, b) and (not strict or ambiguous_ok(j, candidate, b))
                ]  # fmt: skip
                if picks:
                    chosen[j] = picks[0]
                    break
    # A spine with fewer joints than ours (abdomen/chest, Spine/Chest, Spine/Spine1) ends in
    # a name that also fits spine3 ("chest"), which neither pass gives an optional joint;
    # it plays spine2, and the loader spreads its rotation over spine2 and spine3.
    for joint in ("spine2", "spine3"):
        j = JOINT_INDEX[joint]
        if j in chosen or j in excluded:
            continue
        for candidate in BVH_JOINT_CANDIDATES[joint]:
            picks = [b for b in normalized.get(candidate, ()) if fits(j, b)]
            if picks:
                chosen[j] = picks[0]
                break

    # The mapped joints must nest like the canonical tree: each one below the joint of its
    # nearest mapped canonical ancestor (other mapped joints may sit between, as 3ds Max
    # Biped hangs the thighs under its first spine joint and the collars under the neck).
    for j, b in chosen.items():
        top = mapped_ancestor(j)
        if top is None or top in ancestors[b]:
            continue
        owner = next(k for k, v in chosen.items() if v == top)
        what = f"'{names[b]}' (as {JOINT_NAMES[j]})"
        if JOINT_NAMES[j] in user_keys or JOINT_NAMES[owner] in user_keys:
            what = f"joint map '{JOINT_NAMES[j]}' → '{names[b]}'"
        raise MotionError(
            f"{map_source if user_keys else source}: {what} does not hang under "
            f"'{names[top]}' (as {JOINT_NAMES[owner]}) in the hierarchy of "
            f"{source or 'the motion'}; "
            f"{'fix the' if user_keys else 'pass a'} joint map (--joint-map FILE)"
        )
    missing = [j for j in JOINT_NAMES if JOINT_INDEX[j] not in chosen]
    required = [j for j in missing if j not in BVH_OPTIONAL_JOINTS]
    if required:
        first = required[0]
        raise MotionError(
            f"{where}BVH has no joint for {', '.join(required)} (for {first} looked for "
            f"names like {', '.join(BVH_JOINT_CANDIDATES[first][:4])}; pass a joint map "
            "(--joint-map FILE) naming the file's joints)"
        )
    mapping = {JOINT_NAMES[j]: names[b] for j, b in sorted(chosen.items())}
    return mapping, frozenset(JOINT_NAMES[j] for j in excluded)


# ---- small rotation helpers (numpy, batched) ------------------------------------------------


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True).clip(1e-300)


def _shortest_arc(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` taking directions ``a`` onto ``b`` ``(..., 3)``."""
    a, b = np.broadcast_arrays(_unit(np.asarray(a, float)), _unit(np.asarray(b, float)))
    v = np.cross(a, b)
    c = np.sum(a * b, axis=-1)
    opposite = c < -1.0 + 1e-9
    if np.any(opposite):  # half turn about any axis orthogonal to a
        helper = np.where(np.abs(a[..., :1]) > 0.9, [0.0, 1.0, 0.0], [1.0, 0.0, 0.0])
        axis = _unit(np.cross(a, helper))
        v = np.where(opposite[..., None], axis, v)
    K = np.zeros((*v.shape[:-1], 3, 3))
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    K[..., 1, 0], K[..., 2, 0], K[..., 2, 1] = v[..., 2], -v[..., 1], v[..., 0]
    factor = 1.0 / np.where(opposite, 1.0, 1.0 + c)  # unused where opposite
    eye = np.broadcast_to(np.eye(3), K.shape)
    # Opposite: I + 2 K² for a unit axis (a half turn); else I + K + K²/(1 + c).
    return np.where(
        opposite[..., None, None],
        eye + 2.0 * (K @ K),
        eye + K + (K @ K) * factor[..., None, None],
    )


def _frame_alignment(
    canonical: tuple[np.ndarray, np.ndarray], bvh: tuple[np.ndarray, np.ndarray]
) -> np.ndarray:
    """Rotation ``(3, 3)`` taking the canonical (primary, secondary) directions onto the
    BVH's: the primary exactly, the secondary as closely as possible."""

    def basis(primary: np.ndarray, secondary: np.ndarray) -> np.ndarray | None:
        e1 = _unit(primary)
        e2 = secondary - np.dot(secondary, e1) * e1
        if np.linalg.norm(e2) < 1e-9 * max(np.linalg.norm(secondary), 1e-300):
            return None
        e2 = _unit(e2)
        return np.stack([e1, e2, np.cross(e1, e2)], axis=1)

    a, b = basis(*canonical), basis(*bvh)
    if a is None or b is None:
        return _shortest_arc(canonical[0], bvh[0])
    return b @ a.T


def _spine_runs(mapped: set[str], held: frozenset[str]) -> list[list[str]]:
    """Canonical spine chains ``[base, joint, …]`` that one BVH joint stands for: every
    spine joint the file lacks joins the nearest mapped spine joint below it, unless a
    joint map holds it (or one between) at rest. Only runs of two or more are listed:
    abdomen/chest → ``[["spine2", "spine3"]]``; a lone ``Spine`` →
    ``[["spine1", "spine2", "spine3"]]``."""
    runs: list[list[str]] = []
    for joint in ("spine1", "spine2", "spine3"):
        if joint in mapped:
            runs.append([joint])
        elif joint in held or not runs:
            runs.append([])  # a held joint ends the run below it
        else:
            runs[-1].append(joint)
    return [run for run in runs if len(run) > 1 and run[0] in mapped]


def _spread_rotation(global_rotations: np.ndarray, chain: list[int]) -> None:
    """Share the local rotation of ``chain[0]`` equally along the chain, in place.

    ``global_rotations`` ``(T, 24, 3, 3)``; ``chain``: canonical joints, each the parent of
    the next, the base holding the whole rotation ``R`` about its parent. Each joint gets
    ``R^(1/k)`` (the same axis, 1/k of the angle; k = len(chain)), so the top of the chain
    keeps its global rotation and everything above it is unchanged.
    """
    from scipy.spatial.transform import Rotation

    parent_global = global_rotations[:, JOINT_PARENTS[chain[0]]]
    whole = np.swapaxes(parent_global, -1, -2) @ global_rotations[:, chain[0]]
    rotvec = Rotation.from_matrix(whole).as_rotvec()  # (T, 3)
    for step, joint in enumerate(chain[:-1], start=1):
        share = Rotation.from_rotvec(rotvec * (step / len(chain))).as_matrix()
        global_rotations[:, joint] = parent_global @ share
    global_rotations[:, chain[-1]] = parent_global @ whole


# ---- reading and forward kinematics --------------------------------------------------------


def _read_bvh(path: Path) -> tuple[list[str], list[int], np.ndarray, np.ndarray, float, list]:
    """(names, parents, offsets (B, 3), frames (T, C), frame time, per-joint channels)."""
    from bvh import Bvh

    def unreadable(error: Exception) -> MotionError:
        message = " ".join(str(error).split()) or type(error).__name__
        return MotionError(f"{path}: not a readable BVH file ({message})")

    try:
        mocap = Bvh(path.read_text(errors="replace"))
        names = list(mocap.get_joints_names())
    except Exception as error:
        raise unreadable(error) from error
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:  # the parser looks joints up by name
        raise MotionError(f"{path}: BVH joint names must be unique: {', '.join(repeated)}")
    try:
        frames = np.asarray(mocap.frames, dtype=np.float64)
        frame_time = float(mocap.frame_time)
        declared = int(mocap.nframes)
        index = {name: i for i, name in enumerate(names)}
        parents, offsets, channels = [], [], []
        for name in names:
            parent = mocap.joint_parent(name)
            parents.append(-1 if parent is None else index[parent.name])
            offsets.append([float(v) for v in mocap.joint_offset(name)])
            start = mocap.get_joint_channels_index(name)
            channels.append([(start + i, c) for i, c in enumerate(mocap.joint_channels(name))])
    except Exception as error:
        raise unreadable(error) from error
    if not names or frames.ndim != 2 or frames.shape[0] < 1:
        raise MotionError(f"{path}: BVH file has no joints or no frames")
    if frames.shape[0] != declared:
        raise MotionError(f"{path}: BVH declares {declared} frames ('Frames:') but holds "
                          f"{frames.shape[0]}: the file is cut short or damaged")
    if not np.isfinite(frame_time) or frame_time <= 0:
        raise MotionError(f"{path}: BVH frame time must be > 0, got {frame_time}")
    if not np.all(np.isfinite(frames)):
        raise MotionError(f"{path}: BVH frames contain NaN or infinite values")
    width = 1 + max((c for joint in channels for c, _ in joint), default=-1)
    if frames.shape[1] < width:
        raise MotionError(
            f"{path}: BVH frames have {frames.shape[1]} values, the hierarchy needs {width}"
        )
    return names, parents, np.asarray(offsets, dtype=np.float64), frames, frame_time, channels


def _bvh_kinematics(
    parents: list[int], offsets: np.ndarray, frames: np.ndarray, channels: list, path: Path
) -> tuple[np.ndarray, np.ndarray]:
    """Global rotations ``(T, B, 3, 3)`` and positions ``(T, B, 3)`` of every BVH joint, in
    the file's frame and units. Rotation channels compose intrinsically in file order
    (``Zrotation Xrotation Yrotation`` = ``Rz Rx Ry``); position channels are used on the
    root only (added to its offset)."""
    from scipy.spatial.transform import Rotation

    count, joints = frames.shape[0], len(parents)
    rotations = np.empty((count, joints, 3, 3))
    positions = np.empty((count, joints, 3))
    for b, parent in enumerate(parents):
        rot = [(i, c[0].upper()) for i, c in channels[b] if c.lower().endswith("rotation")]
        if rot:
            order = "".join(axis for _, axis in rot)
            if set(order) - set("XYZ"):
                raise MotionError(f"{path}: unknown rotation channels {order!r}")
            local = Rotation.from_euler(
                order, frames[:, [i for i, _ in rot]], degrees=True
            ).as_matrix()
        else:
            local = np.broadcast_to(np.eye(3), (count, 3, 3))
        if parent < 0:
            rotations[:, b] = local
            positions[:, b] = offsets[b]
            for i, c in channels[b]:
                if c.lower().endswith("position"):
                    axis = "XYZ".find(c[0].upper())
                    if axis < 0:
                        raise MotionError(f"{path}: unknown position channel {c!r}")
                    positions[:, b, axis] += frames[:, i]
        else:
            rotations[:, b] = rotations[:, parent] @ local
            positions[:, b] = positions[:, parent] + rotations[:, parent] @ offsets[b]
    return rotations, positions


def _rest_positions(parents: list[int], offsets: np.ndarray) -> np.ndarray:
    """``(B, 3)`` joint positions of the BVH rest pose (all channels zero)."""
    rest = np.zeros_like(offsets)
    for b, parent in enumerate(parents):
        rest[b] = offsets[b] + (rest[parent] if parent >= 0 else 0.0)
    return rest


def _detect_up_axis(rest: np.ndarray, mapping_index: dict[str, int], path: Path) -> str:
    top = mapping_index.get("neck", mapping_index["head"])
    up = rest[top] - rest[mapping_index["pelvis"]]
    axis = int(np.argmax(np.abs(up)))
    if up[axis] > 0 and axis in (1, 2):
        return "yz"[axis - 1]
    raise MotionError(
        f"{path}: cannot tell the BVH up axis: its rest skeleton's pelvis→neck points "
        f"along {'-' if up[axis] < 0 else '+'}{'XYZ'[axis]}; pass up_axis 'y' or 'z'"
    )


# ---- the loader -------------------------------------------------------------------------------


def load_bvh_motion(
    path: str | Path,
    scale: float | str = "auto",
    relative_translation: bool = True,
    joint_map: Mapping[str, str | None] | str | Path | None = None,
    up_axis: str = "auto",
    rest_joints: np.ndarray | None = None,
    retarget: bool = True,
) -> Motion:
    """A BVH file (parsed by the PyPI ``bvh`` package) retargeted onto the 24 joints.

    See the module docstring for the name table, the rest-pose retargeting and units.
    Unmapped intermediate joints (CMU's ``LHipJoint``/``lhipjoint``, ``lowerneck``,
    ``lButtock``; cgspeed ``Neck1``) fold into their mapped neighbours; unmapped leaves
    (fingers, thumbs, eyes) are dropped; both are listed in an
    :class:`UnmappedJointsWarning`, with the canonical joints left at rest and the spine
    joints that share one file joint's rotation.

    Args:
        path: the ``.bvh`` file.
        scale: metres per BVH unit, or ``"auto"``: the recorded leg length
            (hip→knee→ankle, both sides' mean) becomes the target skeleton's.
        relative_translation: subtract the first frame's root position.
        joint_map: canonical joint → BVH joint name overrides (mapping or a
            ``.json``/``.yaml`` file, :func:`read_joint_map`).
        up_axis: ``"y"`` (BVH default: Y up, front +Z), ``"z"`` (Z up, front −Y), or
            ``"auto"`` (from the rest skeleton's pelvis→neck direction).
        rest_joints: ``(24, 3)`` rest joints (metres, canonical T-pose) of the body the
            motion will play on; default :data:`DEFAULT_REST_JOINTS` (Anny's default).
        retarget: align the BVH rest pose to the T-pose (``False`` assumes the BVH rest
            is already our T-pose, the old behaviour; for comparison only).

    Returns:
        The canonical :class:`~gnngarment.body.motion.Motion` at ``1 / Frame Time`` fps:
        rotations ``(T, 24, 3)`` axis-angle, translation ``(T, 3)`` metres (Z up).

    Raises:
        MotionError: unreadable file, missing joints, a bad joint map, an undetectable
            up axis or a bad scale; one line naming the file.
    """
    from scipy.spatial.transform import Rotation

    path = Path(path)
    if not path.is_file():
        raise MotionError(f"{path}: file not found")
    if up_axis not in ("auto", "y", "z"):
        raise MotionError(f"{path}: up_axis must be 'auto', 'y' or 'z', got {up_axis!r}")
    rest_joints = DEFAULT_REST_JOINTS if rest_joints is None else np.asarray(rest_joints, float)
    if rest_joints.shape != (NUM_JOINTS, 3) or not np.all(np.isfinite(rest_joints)):
        raise MotionError(f"{path}: rest_joints must be finite ({NUM_JOINTS}, 3), got "
                          f"{rest_joints.shape}")  # fmt: skip
    names, parents, offsets, frames, frame_time, channels = _read_bvh(path)
    mapping, held = _choose_bvh_joints(names, parents, joint_map, str(path))
    index = {name: i for i, name in enumerate(names)}
    bvh_of = {joint: index[name] for joint, name in mapping.items()}
    spine_runs = _spine_runs(set(mapping), held)

    used = set(bvh_of.values())
    unmapped = [n for n in names if index[n] not in used]
    shared = {joint for run in spine_runs for joint in run[1:]}
    missing = [j for j in JOINT_NAMES if j not in mapping and j not in shared]
    if unmapped or missing or shared:
        spread = "".join(
            f"; '{mapping[run[0]]}' spread over {', '.join(run)}" for run in spine_runs
        )
        warnings.warn(
            f"{path}: BVH joints not mapped onto the canonical skeleton: "
            f"{', '.join(unmapped) or 'none'}; canonical joints left at rest: "
            f"{', '.join(missing) or 'none'}{spread}",
            UnmappedJointsWarning,
            stacklevel=2,
        )

    rest = _rest_positions(parents, offsets)
    if up_axis == "auto":
        up_axis = _detect_up_axis(rest, bvh_of, path)
    C = Y_UP_TO_CANONICAL if up_axis == "y" else np.eye(3)
    with np.errstate(all="ignore"):
        global_rot, global_pos = _bvh_kinematics(parents, offsets, frames, channels, path)
    global_rot = C @ global_rot @ C.T  # (T, B, 3, 3) in the canonical world frame
    global_pos = global_pos @ C.T  # (T, B, 3)
    rest = rest @ C.T
    offsets = offsets @ C.T

    # Units: leg lengths are pose-independent; the target leg over the recorded one.
    def leg(points: np.ndarray, joint_index) -> float:
        return float(np.mean([
            np.linalg.norm(points[joint_index(f"{s}_knee")] - points[joint_index(f"{s}_hip")])
            + np.linalg.norm(points[joint_index(f"{s}_ankle")] - points[joint_index(f"{s}_knee")])
            for s in "LR"
        ]))  # fmt: skip

    if isinstance(scale, str):
        if scale != "auto":
            raise MotionError(f"{path}: scale must be a number or 'auto', got {scale!r}")
        recorded = leg(rest, bvh_of.__getitem__)
        if not recorded > 0:
            raise MotionError(f"{path}: cannot infer the BVH scale (zero leg length)")
        scale = leg(rest_joints, JOINT_INDEX.__getitem__) / recorded
    scale = float(scale)
    if not np.isfinite(scale) or scale <= 0:
        raise MotionError(f"{path}: scale must be a finite number > 0, got {scale}")

    count = frames.shape[0]
    tiny = 1e-6 * leg(rest, bvh_of.__getitem__)
    canonical_global = np.empty((count, NUM_JOINTS, 3, 3))
    alignment = np.empty((NUM_JOINTS, 3, 3))

    def primary_target(joint: str) -> str | None:
        """The nearest mapped joint down the primary chain, a non-zero bone away."""
        child = _PRIMARY_CHILD[joint]
        while child is not None:
            if child in bvh_of and np.linalg.norm(rest[bvh_of[child]] - rest[bvh_of[joint]]) > tiny:
                return child
            child = _PRIMARY_CHILD[child]
        return None

    def driver(start: int, end: int) -> int:
        """The BVH joint whose rotation moves the bone start→end: the parent of the first
        joint with a non-zero offset on the path."""
        path_joints = [end]
        while path_joints[-1] != start:
            path_joints.append(parents[path_joints[-1]])
        for b in reversed(path_joints[:-1]):
            if np.linalg.norm(offsets[b]) > tiny:
                return parents[b]
        return start

    for j, joint in enumerate(JOINT_NAMES):
        parent = JOINT_PARENTS[j]
        if joint not in mapping:
            alignment[j] = alignment[parent]
            canonical_global[:, j] = canonical_global[:, parent]
            continue
        b = bvh_of[joint]
        if not retarget:
            alignment[j] = np.eye(3)
        elif joint == "pelvis":
            # The body frame: up the spine exactly, then left–right through the hips.
            top = "neck" if "neck" in mapping else "head"
            alignment[j] = _frame_alignment(
                (rest_joints[JOINT_INDEX[top]] - rest_joints[0],
                 rest_joints[JOINT_INDEX["L_hip"]] - rest_joints[JOINT_INDEX["R_hip"]]),
                (rest[bvh_of[top]] - rest[b], rest[bvh_of["L_hip"]] - rest[bvh_of["R_hip"]]),
            )  # fmt: skip
        elif joint not in _LIMB_JOINTS or primary_target(joint) is None:
            # Torso (both rests stand upright; bone directions there differ by anatomy,
            # not pose) and leaves: keep the canonical rest relation to the parent.
            alignment[j] = alignment[parent]
        else:
            target = primary_target(joint)
            c = bvh_of[target]
            bone_rest = rest[c] - rest[b]
            alignment[j] = _shortest_arc(
                rest_joints[JOINT_INDEX[target]] - rest_joints[j], bone_rest
            )
            moved = global_rot[:, driver(b, c)]
            bone_now = global_pos[:, c] - global_pos[:, b]
            correction = _shortest_arc((moved @ bone_rest[:, None])[..., 0], bone_now)
            canonical_global[:, j] = correction @ moved @ alignment[j]
            continue
        canonical_global[:, j] = global_rot[:, b] @ alignment[j]

    # A file spine joint that stands for several of ours bends them in equal shares.
    for run in spine_runs:
        _spread_rotation(canonical_global, [JOINT_INDEX[joint] for joint in run])

    local = np.empty_like(canonical_global)
    local[:, 0] = canonical_global[:, 0]
    for j in range(1, NUM_JOINTS):
        parent_global = canonical_global[:, JOINT_PARENTS[j]]
        local[:, j] = np.swapaxes(parent_global, -1, -2) @ canonical_global[:, j]
    rotations = Rotation.from_matrix(local.reshape(-1, 3, 3)).as_rotvec()
    translation = global_pos[:, bvh_of["pelvis"]] * scale
    if relative_translation:
        translation = translation - translation[:1]
    return Motion(rotations.reshape(count, NUM_JOINTS, 3), translation, 1.0 / frame_time, str(path))
