"""Fuzz gmuk.lie (so3, se3, euler) with hostile inputs (issue #15).

Each map either returns finite numbers that mean what they should (round trips hold,
results are on the group) or raises a GmukError; honest real input of the right shape is
never refused, dishonest input (bool, complex, str, objects) never accepted.
"""

from __future__ import annotations

import numpy as np
from fuzz_inputs import REFUSED, arrays, fuzz_pair, honest_real, outcome, poses, rotations
from hypothesis import strategies as st

from gmuk.lie import euler, se3, so3


def _refuses_dishonest(entry: str, value, out) -> None:
    if not honest_real(value):
        assert out is REFUSED, f"{entry} accepted {value!r:.200} (not honest real data)"


def _batchable(value, tail):
    """``value`` as float if honest real data with trailing shape ``tail``, else None."""
    if not honest_real(value):
        return None
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        return None
    k = len(tail)
    return a if a.ndim >= k and a.shape[a.ndim - k :] == tail else None


# ----------------------------------------------------------------------------- vectors
def check_so3_vector_maps(w) -> None:
    ref = _batchable(w, (3,))
    H = outcome("so3.hat", so3.hat, w)
    _refuses_dishonest("so3.hat", w, H)
    if ref is not None and np.isfinite(ref).all():
        assert H is not REFUSED, f"so3.hat refused honest {w!r:.200}"
        np.testing.assert_array_equal(so3.vee(H), ref)  # nothing changed on the way
    R = outcome("so3.exp", so3.exp, w)
    _refuses_dishonest("so3.exp", w, R)
    if R is not REFUSED:
        assert ref is not None
        RtR = np.swapaxes(R, -1, -2) @ R
        assert np.abs(RtR - np.eye(3)).max(initial=0) < 1e-12, "so3.exp left SO(3)"
        if R.size and np.abs(ref).max() < 1e6:  # where the angle still means something
            assert np.abs(so3.exp(so3.log(R)) - R).max() < 1e-9


def check_se3_vector_maps(xi) -> None:
    ref = _batchable(xi, (6,))
    for entry, fn in (
        ("se3.hat", se3.hat),
        ("se3.exp", se3.exp),
        ("se3.ad", se3.ad),
        ("se3.ad_star", se3.ad_star),
        ("se3.dexp", se3.dexp),
        ("se3.dexp_inv", se3.dexp_inv),
    ):
        out = outcome(entry, fn, xi)
        _refuses_dishonest(entry, xi, out)
        if out is not REFUSED:
            assert ref is not None
        elif ref is not None and entry in ("se3.hat", "se3.ad", "se3.ad_star"):
            # linear maps of honest finite input cannot fail
            assert not np.isfinite(ref).all(), f"{entry} refused honest {xi!r:.200}"
        if entry == "se3.hat" and out is not REFUSED:
            np.testing.assert_array_equal(se3.vee(out), ref)
        if entry == "se3.exp" and out is not REFUSED:
            assert np.all(out[..., 3, :] == [0, 0, 0, 1]), "se3.exp: last row is not [0 0 0 1]"
        if entry == "se3.dexp" and out is not REFUSED and ref.size:
            theta = np.linalg.norm(ref[..., :3], axis=-1)
            inv = outcome("se3.dexp_inv", se3.dexp_inv, ref)
            if inv is not REFUSED and theta.max() < 3.0 and np.abs(ref).max() < 1e3:
                assert np.abs(out @ inv - np.eye(6)).max() < 1e-8


# ---------------------------------------------------------------------------- matrices
def check_so3_matrix_maps(R) -> None:
    w = outcome("so3.log", so3.log, R)
    _refuses_dishonest("so3.log", R, w)
    if w is not REFUSED:
        # accepted: a rotation to 1e-9, and log recovers it, no silent repair
        ref = np.asarray(R, dtype=float)
        assert np.abs(so3.exp(w) - ref).max(initial=0) < 1e-7, "so3.log accepted a non-rotation"
    v = outcome("so3.vee", so3.vee, R)
    _refuses_dishonest("so3.vee", R, v)
    if v is not REFUSED:
        ref = np.asarray(R, dtype=float)
        scale = max(1.0, float(np.abs(ref).max(initial=0)))
        assert np.abs(so3.hat(v) - ref).max(initial=0) <= 1e-8 * scale, "vee dropped a part"
    for seq in ("321", "313"):
        angles = outcome("euler.from_matrix", euler.from_matrix, R, seq)
        _refuses_dishonest("euler.from_matrix", R, angles)
        if angles is not REFUSED:
            back = euler.to_matrix(angles, seq)
            assert np.abs(back - np.asarray(R, dtype=float)).max(initial=0) < 1e-7


def check_se3_matrix_maps(g) -> None:
    for entry, fn in (
        ("se3.log", se3.log),
        ("se3.Ad", se3.Ad),
        ("se3.inverse", se3.inverse),
        ("se3.vee", se3.vee),
    ):
        out = outcome(entry, fn, g)
        _refuses_dishonest(entry, g, out)
        if out is REFUSED:
            continue
        ref = np.asarray(g, dtype=float)
        if entry == "se3.log":
            back = se3.exp(out)
            scale = max(1.0, float(np.abs(ref[..., :3, 3]).max(initial=0)))
            assert np.abs(back - ref).max(initial=0) <= 1e-7 * scale, "se3.log: no round trip"
        if entry == "se3.vee":
            scale = max(1.0, float(np.abs(ref).max(initial=0)))
            assert np.abs(se3.hat(out) - ref).max(initial=0) <= 1e-8 * scale


def check_euler_to_matrix(args) -> None:
    angles, seq = args
    R = outcome("euler.to_matrix", euler.to_matrix, angles, seq)
    _refuses_dishonest("euler.to_matrix", angles, R)
    if R is not REFUSED:
        assert seq in ("321", "313")
        RtR = np.swapaxes(R, -1, -2) @ R
        assert np.abs(RtR - np.eye(3)).max(initial=0) < 1e-12


vec3 = st.one_of(arrays((3,)), arrays((2, 3)))
vec6 = st.one_of(arrays((6,)), arrays((2, 6)))
mat3 = st.one_of(rotations(), arrays((3, 3)), st.lists(rotations(), min_size=1, max_size=3))
mat4 = st.one_of(poses(), st.lists(poses(), min_size=1, max_size=2))
seqs = st.one_of(
    st.sampled_from(["321", "313"]),
    st.sampled_from(["123", "", "3 2 1", None, 321, b"321", ("3", "2", "1")]),
)

(
    test_so3_vector_maps_give_finite_results_or_gmuk_errors,
    test_so3_vector_maps_give_finite_results_or_gmuk_errors_slow,
) = fuzz_pair(vec3, check_so3_vector_maps, fast=80, slow=1500)
(
    test_se3_vector_maps_give_finite_results_or_gmuk_errors,
    test_se3_vector_maps_give_finite_results_or_gmuk_errors_slow,
) = fuzz_pair(vec6, check_se3_vector_maps, fast=80, slow=1500)
(
    test_so3_matrix_maps_refuse_non_rotations_and_never_repair,
    test_so3_matrix_maps_refuse_non_rotations_and_never_repair_slow,
) = fuzz_pair(mat3, check_so3_matrix_maps, fast=80, slow=1500)
(
    test_se3_matrix_maps_refuse_non_elements_and_never_repair,
    test_se3_matrix_maps_refuse_non_elements_and_never_repair_slow,
) = fuzz_pair(mat4, check_se3_matrix_maps, fast=80, slow=1500)
(
    test_euler_to_matrix_gives_rotations_or_gmuk_errors,
    test_euler_to_matrix_gives_rotations_or_gmuk_errors_slow,
) = fuzz_pair(st.tuples(vec3, seqs), check_euler_to_matrix, fast=60, slow=1000)
