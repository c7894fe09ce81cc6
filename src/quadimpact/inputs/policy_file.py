"""Learned recovery policies: the residual network's weights in a ``.npz`` file.

A policy file holds the arrays of the residual network that corrects the
recovery law from the detection on (``core/controllers/residual.py``,
docs/LEARNING.md sections 12 and 14)::

    w1 (nh, 24)   b1 (nh,)   w2 (3, nh)   b2 (3,)
    thrust_scale ()    the largest thrust correction, a fraction of m g
    rate_scale_rad_s () the largest roll and pitch rate-reference correction, rad/s
    last_stage ()      optional: the last stage it acts in, 4 (the default: from the
                       detection to the recovery) or 5 (the hover too)
    hover_centred ()   optional: 1 if its correction in the hover stage is zero at
                       the hover itself (0, the default: not)
    hover_hand_over () optional: 1 if in the hover stage it acts only until the law has
                       captured the point it holds (0, the default: all through)
    hover_fade_s (2,)  optional: ``(from, to)``, s after the detection: its correction
                       in the hover stage fades linearly to 0 between them
                       (``0 <= from < to <= 2``; (0, 0), the default: no fade)
    meta ()            optional: a JSON text of how it was trained

``--policy learned`` names the policy shipped with quadimpact
(``inputs/policies/learned.npz``: a residual in every stage, trained for the
``onboard`` and ``ideal`` sensors, docs/LEARNING.md 15); ``learned-imu`` the one
shipped before it (``learned-imu.npz``: stages 1-4, trained for the ``impact``
sensors, docs/LEARNING.md 12); any other value is a file path. Flying a
policy needs NumPy only: the compiled loop evaluates the network itself, and
:meth:`PolicyWeights.outputs` is the same network in NumPy.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from quadimpact.core.controller_slots import (
    F_SCALE_M_S2,
    MAX_HIDDEN,
    N_FEATURES,
    N_OUTPUTS,
    T_CAP_S,
)
from quadimpact.errors import InputError, short_path
from quadimpact.linalg import matvec

__all__ = [
    "SHIPPED_POLICIES",
    "PolicyWeights",
    "checked_fade",
    "checked_policy",
    "hover_features",
    "initial_policy",
    "load_policy",
    "policy_path",
    "policy_ref",
    "record_policy",
    "save_policy",
]

#: The stages a policy may act up to: 4 (from the detection to the recovery) or 5 (the
#: hover too).
LAST_STAGES = (4, 5)

#: Policies shipped with quadimpact, by name: their files in ``inputs/policies/``.
SHIPPED_POLICIES = {"learned": "learned.npz", "learned-imu": "learned-imu.npz"}

_POLICY_DIR = Path(__file__).parent / "policies"


@dataclass(frozen=True)
class PolicyWeights:
    """A residual policy's weights (module docstring), with where they came from.

    Attributes
    ----------
    w1, b1, w2, b2 : numpy.ndarray
        The network's weights, shapes ``(nh, 24)``, ``(nh,)``, ``(3, nh)``, ``(3,)``.
    thrust_scale : float
        The largest thrust correction as a fraction of the hover thrust ``m g``.
    rate_scale_rad_s : float
        The largest roll and pitch rate-reference correction, rad/s.
    last_stage : int
        The last stage of the law it corrects: 4 (stages 1-4, the law alone
        in the hover) or 5 (every stage from the detection on).
    hover_centred : bool
        In the hover stage, the correction minus its value at the hover itself
        (vehicle level and at rest, ``core/controllers/residual.py``), so that
        the law's hover stays where it is.
    hover_hand_over : bool
        In the hover stage, act only while the law brakes: no correction once
        the law has captured the point it holds (``core/controllers/residual.py``).
    hover_fade_s : tuple of float
        ``(from, to)``, s after the detecting sample: in the hover stage the
        correction is multiplied by a weight that is 1 until ``from`` and falls
        linearly to 0 at ``to`` (``0 <= from < to <= 2``); ``(0, 0)``: no fade.
    meta : dict
        How the weights were made (training script, seeds, ...), as saved.
    sha256 : str
        Digest of the weights (``vector()``'s bytes): the policy's identity.
    path : str
        The file read ("" for weights made in memory).
    """

    w1: np.ndarray
    b1: np.ndarray
    w2: np.ndarray
    b2: np.ndarray
    thrust_scale: float
    rate_scale_rad_s: float
    last_stage: int = 4
    hover_centred: bool = False
    hover_hand_over: bool = False
    hover_fade_s: tuple[float, float] = (0.0, 0.0)
    meta: dict = field(default_factory=dict)
    sha256: str = ""
    path: str = ""

    @property
    def hidden(self) -> int:
        """Width of the hidden layer."""
        return int(self.w1.shape[0])

    def vector(self) -> np.ndarray:
        """The weights as one vector ``[w1, b1, w2, b2]`` (row-major), the trainer's parameters."""
        return np.concatenate([self.w1.ravel(), self.b1, self.w2.ravel(), self.b2])

    def with_vector(self, theta: np.ndarray, **meta: Any) -> PolicyWeights:
        """These weights replaced by ``theta`` (as :meth:`vector` lays them out)."""
        nh = self.hidden
        theta = np.asarray(theta, dtype=float)
        a = nh * N_FEATURES
        w1 = theta[:a].reshape(nh, N_FEATURES)
        b1 = theta[a : a + nh]
        w2 = theta[a + nh : a + nh + N_OUTPUTS * nh].reshape(N_OUTPUTS, nh)
        b2 = theta[a + nh + N_OUTPUTS * nh :]
        new = replace(self, w1=w1.copy(), b1=b1.copy(), w2=w2.copy(), b2=b2.copy(), path="")
        return replace(new, meta={**self.meta, **meta}, sha256=_digest(new))

    def with_hand_over(self, hand_over: bool = True) -> PolicyWeights:
        """These weights with ``hover_hand_over`` set (see the class)."""
        new = replace(self, hover_hand_over=bool(hand_over), path="")
        return replace(new, sha256=_digest(new))

    def with_fade(self, from_s: float, to_s: float) -> PolicyWeights:
        """These weights with the hover stage's fade ``(from_s, to_s)`` (s after the
        detection; ``(0, 0)``: none), checked as a file's ``hover_fade_s``."""
        fade = checked_fade(np.array([from_s, to_s], dtype=float))
        new = replace(self, hover_fade_s=fade, path="")
        return replace(new, sha256=_digest(new))

    def outputs(self, features: np.ndarray, gravity_m_s2: float = 9.81) -> np.ndarray:
        """The policy's three outputs for ``features`` ``(..., 24)`` (NumPy only).

        Each in (-1, 1), or for a hover-centred policy in the hover stage (feature
        20 set) the network's outputs minus those at the hover (:func:`hover_features`,
        with ``gravity_m_s2``, m/s^2), each in (-2, 2). The same arithmetic on every
        CPU (``quadimpact.linalg``'s sums in index order and the C library's
        ``tanh``, as the compiled loop), not NumPy's vectorised kernels.
        """
        f = np.asarray(features, dtype=float)
        out = self._network(f)
        hover = f[..., 20:21] > 0.5
        if self.hover_centred:
            out = np.where(hover, out - self._network(hover_features(f, gravity_m_s2)), out)
        if self.hover_fade_s[1] > 0.0:
            out = np.where(hover, out * self.fade_weight(f[..., 15:16]), out)
        return out

    def fade_weight(self, since_s: np.ndarray) -> np.ndarray:
        """The hover stage's weight ``since_s`` seconds after the detection (1: no fade)."""
        a, b = self.hover_fade_s
        t = np.asarray(since_s, dtype=float)
        if b <= 0.0:
            return np.ones_like(t)
        w = np.where(t <= a, 1.0, (b - t) / (b - a))
        return np.where(t >= b, 0.0, w)

    def _network(self, f: np.ndarray) -> np.ndarray:
        h = _tanh(matvec(self.w1, f) + self.b1)
        return _tanh(matvec(self.w2, h) + self.b2)

    def block(self) -> np.ndarray:
        """The compiled loop's block ``[nh, s_T, s_w, last stage, hover-centred, hand over,
        fade from, fade to, W1, b1, W2, b2]`` (residual.py)."""
        head = [self.hidden, self.thrust_scale, self.rate_scale_rad_s, self.last_stage]
        flags = [float(self.hover_centred), float(self.hover_hand_over), *self.hover_fade_s]
        head = np.array([*head, *flags], dtype=float)
        return np.concatenate([head, self.vector()])


_tanh_object = np.frompyfunc(math.tanh, 1, 1)


def _tanh(x: np.ndarray) -> np.ndarray:
    """``tanh`` element by element with the C library's scalar function."""
    return np.asarray(_tanh_object(x), dtype=float)


def hover_features(features: np.ndarray, gravity_m_s2: float) -> np.ndarray:
    """``features`` ``(..., 24)`` with the vehicle level and at rest, at its hover.

    The NumPy twin of ``core/controllers/residual.py``'s: gravity along body z,
    no velocity or body rates, the accelerometer reading ``-g`` along body z
    (``gravity_m_s2``, m/s^2), the law at its hover thrust with zero rate
    references; the wall normal, the time and the stage kept.
    """
    h = np.array(features, dtype=float, copy=True)
    h[..., 0:2] = 0.0
    h[..., 2] = 1.0
    h[..., 6:14] = 0.0
    h[..., 14] = -gravity_m_s2 / F_SCALE_M_S2
    h[..., 21:24] = 0.0
    return h


def _digest(p: PolicyWeights) -> str:
    h = hashlib.sha256(np.ascontiguousarray(p.vector(), dtype="<f8").tobytes())
    h.update(np.array([p.thrust_scale, p.rate_scale_rad_s], dtype="<f8").tobytes())
    if p.last_stage != 4:  # a policy of stages 1-4 keeps the digest it had before last_stage
        h.update(np.array([p.last_stage], dtype="<f8").tobytes())
    if p.hover_centred:  # and one not hover-centred the digest it had before that
        h.update(b"hover_centred")
    if p.hover_hand_over:  # and one that does not hand over the digest it had before that
        h.update(b"hover_hand_over")
    if p.hover_fade_s[1] > 0.0:  # and one without a fade the digest it had before that
        h.update(np.array(p.hover_fade_s, dtype="<f8").tobytes())
    return h.hexdigest()


def policy_path(name: str) -> Path:
    """The file of policy ``name``: a shipped policy's (``learned``) or the path given."""
    if name in SHIPPED_POLICIES:
        return _POLICY_DIR / SHIPPED_POLICIES[name]
    return Path(name).expanduser()


def policy_ref(name: str) -> str:
    """How a run records policy ``name``: a shipped name as is, a file as its absolute path."""
    return name if name in SHIPPED_POLICIES else str(policy_path(name).resolve())


def checked_policy(name: str) -> tuple[str, str]:
    """A study's ``policy`` option checked: ``(policy_ref(name), sha256 of its weights)``.

    Raises :class:`InputError` as :func:`load_policy`.
    """
    return policy_ref(name), load_policy(name).sha256


def record_policy(options: dict[str, Any], sha256: str) -> dict[str, Any]:
    """A study's options (``study.json``) with its policy recorded, in place: ``policy``
    dropped when None (a study without one keeps the identity it had before policies
    existed, so its folder resumes), else the weights' ``policy_sha256`` beside it."""
    options.pop("_policy_sha256", None)
    if options.get("policy") is None:
        options.pop("policy", None)
    else:
        options["policy_sha256"] = sha256
    return options


def load_policy(name: str | Path) -> PolicyWeights:
    """Read and check a policy file (``learned``: the shipped one; else a ``.npz`` path).

    Raises
    ------
    InputError
        One line naming the file and the rule broken: missing file, not a
        ``.npz`` archive, a missing array, wrong shapes, non-finite numbers,
        a hidden layer wider than ``MAX_HIDDEN``.
    """
    path = policy_path(str(name))
    where = f"policy: {short_path(str(path))}"
    if not path.is_file():
        shipped = ", ".join(sorted(SHIPPED_POLICIES))
        raise InputError(f"{where}: no such file (give a .npz policy file or one of: {shipped})")
    try:
        with np.load(path, allow_pickle=False) as npz:
            arrays = {k: np.array(npz[k]) for k in npz.files}
    except Exception as exc:  # noqa: BLE001 - any unreadable file is the same user error
        raise InputError(f"{where}: not a .npz policy file ({type(exc).__name__})") from None
    need = ("w1", "b1", "w2", "b2", "thrust_scale", "rate_scale_rad_s")
    missing = [k for k in need if k not in arrays]
    if missing:
        raise InputError(f"{where}: missing array(s) {', '.join(missing)}")
    try:
        w = {k: np.asarray(arrays[k], dtype=float) for k in need}
    except (TypeError, ValueError):
        raise InputError(f"{where}: every array must be numeric") from None
    nh = w["w1"].shape[0] if w["w1"].ndim == 2 else -1
    shapes = {
        "w1": (nh, N_FEATURES),
        "b1": (nh,),
        "w2": (N_OUTPUTS, nh),
        "b2": (N_OUTPUTS,),
        "thrust_scale": (),
        "rate_scale_rad_s": (),
    }
    for k, shape in shapes.items():
        if nh < 1 or w[k].shape != shape:
            raise InputError(
                f"{where}: {k}: must be {shape if nh >= 1 else '(nh, 24)'} with w1 (nh, 24), "
                f"1 <= nh <= {MAX_HIDDEN} (got {w[k].shape})"
            )
    if nh > MAX_HIDDEN:
        raise InputError(f"{where}: w1: hidden width must be <= {MAX_HIDDEN} (got {nh})")
    for k in need:
        if not np.all(np.isfinite(w[k])):
            raise InputError(f"{where}: {k}: must be finite")
    for k in ("thrust_scale", "rate_scale_rad_s"):
        if float(w[k]) < 0:
            raise InputError(f"{where}: {k}: must be >= 0 (got {float(w[k])})")
    last_stage = 4
    if "last_stage" in arrays:
        raw = np.asarray(arrays["last_stage"])
        if raw.shape != () or raw.dtype.kind not in "iuf" or float(raw) not in LAST_STAGES:
            got = raw.tolist()
            raise InputError(f"{where}: last_stage: must be one number, 4 or 5 (got {got!r})")
        last_stage = int(raw)
    hover_centred = _optional_flag(arrays, "hover_centred", where)
    hover_hand_over = _optional_flag(arrays, "hover_hand_over", where)
    hover_fade_s = (0.0, 0.0)
    if "hover_fade_s" in arrays:
        hover_fade_s = checked_fade(arrays["hover_fade_s"], where)
    meta: dict = {}
    if "meta" in arrays:
        try:
            meta = json.loads(str(arrays["meta"]))
        except ValueError:
            raise InputError(f"{where}: meta: must be a JSON text") from None
    p = PolicyWeights(
        w["w1"],
        w["b1"],
        w["w2"],
        w["b2"],
        float(w["thrust_scale"]),
        float(w["rate_scale_rad_s"]),
        last_stage=last_stage,
        hover_centred=hover_centred,
        hover_hand_over=hover_hand_over,
        hover_fade_s=hover_fade_s,
        meta=meta,
        path=str(path),
    )
    return replace(p, sha256=_digest(p))


def _optional_flag(arrays: dict[str, np.ndarray], name: str, where: str) -> bool:
    """A file's optional 0-or-1 array ``name`` (absent: False); one-line error otherwise."""
    if name not in arrays:
        return False
    raw = np.asarray(arrays[name])
    if raw.shape != () or raw.dtype.kind not in "biuf" or float(raw) not in (0.0, 1.0):
        raise InputError(f"{where}: {name}: must be one number, 0 or 1 (got {raw.tolist()!r})")
    return bool(raw)


def checked_fade(value: Any, where: str = "policy") -> tuple[float, float]:
    """``hover_fade_s`` checked: two numbers ``(from, to)`` s, ``0 <= from < to <= 2``, or
    ``(0, 0)`` (no fade). Raises :class:`InputError` naming ``where`` and the rule."""
    raw = np.asarray(value)
    rule = "must be two numbers (from, to) s with 0 <= from < to <= 2, or (0, 0)"
    if raw.shape != (2,) or raw.dtype.kind not in "iuf":
        raise InputError(f"{where}: hover_fade_s: {rule} (got {raw.tolist()!r})")
    a, b = (float(v) for v in raw)
    if (a, b) != (0.0, 0.0) and not (0.0 <= a < b <= T_CAP_S):
        raise InputError(f"{where}: hover_fade_s: {rule} (got {[a, b]!r})")
    return a, b


def save_policy(policy: PolicyWeights, path: str | Path) -> Path:
    """Write ``policy`` as a ``.npz`` policy file (float64, its ``meta`` as JSON text)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp.npz")
    np.savez(
        tmp,
        w1=policy.w1,
        b1=policy.b1,
        w2=policy.w2,
        b2=policy.b2,
        thrust_scale=np.float64(policy.thrust_scale),
        rate_scale_rad_s=np.float64(policy.rate_scale_rad_s),
        last_stage=np.int64(policy.last_stage),
        hover_centred=np.int64(policy.hover_centred),
        hover_hand_over=np.int64(policy.hover_hand_over),
        hover_fade_s=np.array(policy.hover_fade_s, dtype=float),
        meta=np.array(json.dumps(policy.meta, sort_keys=True)),
    )
    tmp.replace(path)
    return path


def initial_policy(
    hidden: int,
    thrust_scale: float,
    rate_scale_rad_s: float,
    seed: int,
    last_stage: int = 4,
    hover_centred: bool = False,
) -> PolicyWeights:
    """A new policy that flies the law exactly: random ``w1`` (scale 1/sqrt(24)), a zero
    output layer (``seed``: of ``w1``'s draw; the scales, ``last_stage`` and
    ``hover_centred`` as :class:`PolicyWeights`')."""
    if last_stage not in LAST_STAGES:
        raise InputError(f"policy: last_stage: must be 4 or 5 (got {last_stage})")
    if not 1 <= hidden <= MAX_HIDDEN:
        raise InputError(f"policy: hidden: must be in 1..{MAX_HIDDEN} (got {hidden})")
    for name, value in (("thrust_scale", thrust_scale), ("rate_scale_rad_s", rate_scale_rad_s)):
        if not (math.isfinite(value) and value >= 0):
            raise InputError(f"policy: {name}: must be finite and >= 0 (got {value})")
    rng = np.random.default_rng(seed)
    p = PolicyWeights(
        rng.normal(0.0, 1.0 / math.sqrt(N_FEATURES), (hidden, N_FEATURES)),
        np.zeros(hidden),
        np.zeros((N_OUTPUTS, hidden)),
        np.zeros(N_OUTPUTS),
        float(thrust_scale),
        float(rate_scale_rad_s),
        last_stage=int(last_stage),
        hover_centred=bool(hover_centred),
    )
    return replace(p, sha256=_digest(p))
