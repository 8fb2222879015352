"""Assignment 02: registration, check() rejecting wrong answers, and an open exercise that is fair."""
from __future__ import annotations

import numpy as np
import pytest

from robocourse.lessons.omni_localization import exercises as module
from robocourse.grading import check
from robocourse.lessons import exercises_for
from tests.conftest import assert_check_passes
from robokit.vision import histogram_distance

EXERCISES = {ex.id: ex for ex in module.EXERCISES}


def test_assignment_is_registered():
    assert module.ASSIGNMENT == "02_omni_localization"
    assert [e.id for e in exercises_for("02_omni_localization")] == list(EXERCISES)
    assert 7 <= len(EXERCISES) <= 8 and len(module.WRITTEN) >= 2


def test_cases_differ_between_seeds():
    for ex in EXERCISES.values():
        assert ex.make_cases(1) != ex.make_cases(2) or ex.id in ("02.path_following_command",), ex.id


def _wrong_hsi(pixels):  # forgets the 2 pi - theta branch for B > G
    p = np.asarray(pixels, float)
    r, g, b = p[:, 0], p[:, 1], p[:, 2]
    if p.ndim != 2 or p.shape[1] != 3 or np.isnan(p).any() or (p < 0).any() or (p > 1).any():
        raise ValueError("pixels")
    den = np.sqrt((r - g) ** 2 + (r - b) * (g - b))
    theta = np.arccos(np.clip(np.divide(0.5 * ((r - g) + (r - b)), den, out=np.ones_like(r), where=den > 0), -1, 1))
    return np.column_stack([theta, p.max(1) - p.min(1), p.mean(1)])


def _wrong_histogram(image, bins=32, min_saturation=0.15, min_intensity=0.04, max_intensity=0.98):
    if bins < 1 or np.shape(image)[-1] != 3:
        raise ValueError("bins")
    hsi = module.rgb_to_hsi(image)                      # counts every pixel, grey ones too
    h = np.bincount(np.minimum((hsi[..., 0] * bins / (2 * np.pi)).astype(int), bins - 1).ravel(), minlength=bins)
    return h / h.sum()


def _wrong_distance(h, H):  # squared distance, not Eq. (5)
    h, H = np.asarray(h, float), np.asarray(H, float)
    if h.shape[-1] != H.shape[-1]:
        raise ValueError("H")
    return ((H - h) ** 2).sum(axis=-1)


def _wrong_counts(query, node_descriptors, candidates, ratio=0.8):  # nearest neighbour, no ratio test
    if any(not 0 <= c < len(node_descriptors) for c in candidates):
        raise ValueError("candidates")
    q = np.asarray(query, float)
    out = []
    for c in candidates:
        t = np.asarray(node_descriptors[c], float)
        if t.shape[1] != q.shape[1]:
            raise ValueError("descriptors")
        out.append(len(q))
    return np.array(out)


def _wrong_sweep(poses, variances, edges, measurements, edge_variances, fixed=0):  # moves the fixed node too
    if np.any(np.asarray(edge_variances) < 0) or np.max(edges) >= len(poses):
        raise ValueError("edge_variances")
    new = np.asarray(poses, float) + 0.01
    return new, np.asarray(variances, float)


def _wrong_command(d, theta_tilde, curvature, v, k2, k3):  # drops the curvature term
    if k2 < 0 or k3 < 0 or 1 - curvature * d <= 0:
        raise ValueError("k2")
    return -k3 * abs(v) * theta_tilde - k2 * v * d * np.sinc(theta_tilde / np.pi)


def _wrong_update(x, P, z, H, R, angles=()):  # no angle wrapping
    x, P, z, H, R = (np.asarray(a, float) for a in (x, P, z, H, R))
    if np.any(np.linalg.eigvalsh(R) <= 0) or len(z) != len(H):
        raise ValueError("R")
    S = H @ P @ H.T + R
    K = P @ H.T @ np.linalg.inv(S)
    return x + K @ (z - H @ x), (np.eye(len(x)) - K @ H) @ P


def _coarse_only(query_histogram, query_descriptors, node_histograms, node_descriptors):
    if len(node_histograms) == 0:
        raise ValueError("node_histograms")
    return int(np.argmin(histogram_distance(query_histogram, node_histograms)))


WRONG = {"02.rgb_to_hsi": _wrong_hsi, "02.hue_histogram": _wrong_histogram,
         "02.histogram_distance": _wrong_distance, "02.fine_stage_counts": _wrong_counts,
         "02.relax_sweep": _wrong_sweep, "02.path_following_command": _wrong_command,
         "02.ekf_update": _wrong_update, "02.recognise_node": _coarse_only}


@pytest.mark.parametrize("exercise_id", list(EXERCISES))
def test_check_fails_a_wrong_implementation(exercise_id, capsys):
    with pytest.raises(AssertionError, match=exercise_id) as failed:
        check(exercise_id, WRONG[exercise_id])
    assert "FAIL" in str(failed.value)          # the failed cases, in the message students see


@pytest.mark.parametrize("exercise_id", list(EXERCISES))
def test_check_passes_the_reference(exercise_id, capsys):
    assert_check_passes(exercise_id, EXERCISES[exercise_id].answer, len(EXERCISES[exercise_id].make_cases(2024)))


@pytest.mark.parametrize("seed", range(12))
def test_the_open_exercise_is_fair(seed):
    """Its expected answer is the node found by matching against every node (no coarse stage), and the
    colour histogram alone is fooled in the look-alike cases, so the method matters."""
    fooled = 0
    for case in EXERCISES["02.recognise_node"].make_cases(seed):
        if case.raises:
            continue
        q_hist, q_desc, hists, nodes = case.args
        exhaustive = module.fine_stage_counts(q_desc, nodes, list(range(len(nodes))))
        answer = module.recognise_node(*case.args)
        assert answer == int(np.argmax(exhaustive)) and np.sort(exhaustive)[-1] > 2 * np.sort(exhaustive)[-2]
        fooled += _coarse_only(*case.args) != answer
    assert fooled >= 1
