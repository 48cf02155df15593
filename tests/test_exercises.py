"""Every exercise of every notebook grades right: its solution passes, a plausible wrong answer is rejected.

The exercises are found in the notebooks by ``scripts/instructor_sheet.py`` (:func:`exercises`): a Markdown cell
starting ``**Exercise``, the cells that call ``bl.exercise.check/choice/predict`` (the stubs the student sees)
and the cells tagged ``solution``. The student's part of a stub cell is a function whose body raises
``NotImplementedError`` or an answer variable set to ``None`` (:func:`student_names`).

Running a whole notebook takes minutes, so each notebook's exercises run in isolation: only the earlier cells
that define what the exercise cells use (found by the names they read, transitively) run first, then for each
exercise, in notebook order:

1. the stub cell as the student gets it: every check returns ``None`` (not done yet);
2. for each wrong answer of :data:`WRONG`: its definition, then the stub cell without the stub, up to its last
   check: every check of that answer returns ``False``;
3. for each right answer of :data:`RIGHT` (written otherwise than the solution: another dtype, an in-place
   update, another formula, a list or a torch tensor): the whole stub cell, then the exercise's other cells before
   its solution (what the student runs next, e.g. a ``check`` cell that uses the answer): every check of that
   answer returns ``True`` and no later line fails on the answer's type;
4. the solution cell: every check of the exercise returns ``True``.

A new exercise needs a row in :data:`WRONG` (``test_every_exercise_has_a_wrong_answer`` says which).
"""

from __future__ import annotations

import ast
import builtins
import importlib.util
import json
import os
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((REPO / "notebooks").glob("[0-9][0-9]_*.ipynb"))


def _sheet_module():
    spec = importlib.util.spec_from_file_location(
        "instructor_sheet", REPO / "scripts" / "instructor_sheet.py"
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("instructor_sheet", module)
    spec.loader.exec_module(module)
    return sys.modules["instructor_sheet"]


sheet = _sheet_module()

_SPAN = (
    "def span_word_ids(words, n_frames, fps, vocab):\n    t = np.arange(n_frames) / fps\n"
    "    ids = np.array([vocab.get(w, {unk}) for w in words.words], dtype=np.int64)\n"
    "    k = np.searchsorted(words.starts, t, side='{side}') - 1\n"
    "    inside = (k >= 0) & (t {before} words.ends[np.maximum(k, 0)])\n"
    "    out = np.zeros(n_frames, dtype=np.int64)\n    out[inside] = ids[k[inside]]\n    return out"
)

#: (notebook number, the student's name) -> plausible wrong answers (source defining that name).
WRONG: dict[tuple[str, str], list[str]] = {
    ("00", "emotion_of_sequence"): [  # the block's last id counted in the next block
        "def emotion_of_sequence(seq):\n    return int(np.searchsorted([64, 72, 80, 86, 94, 102, 110, 118], seq, side='right'))"
    ],
    ("00", "speech_split"): [  # forgot the first sequence of each emotion block
        "def speech_split(seq):\n    if seq <= 8:\n        return 'test'\n"
        "    if 57 <= seq <= 64 or seq in (72, 80, 86, 94, 102, 110, 118):\n        return 'val'\n    return 'train'"
    ],
    ("00", "subset_minutes"): [  # seconds, not minutes
        "def subset_minutes(index, **criteria):\n    return sum(r.duration for r in index.where(**criteria))"
    ],
    ("01", "euler_xyz_to_matrix"): [  # the rotations multiplied in the wrong order
        "def euler_xyz_to_matrix(angles):\n    a, b, c = np.deg2rad(np.asarray(angles, dtype=float))\n"
        "    rx = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])\n"
        "    ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])\n"
        "    rz = np.array([[np.cos(c), -np.sin(c), 0], [np.sin(c), np.cos(c), 0], [0, 0, 1]])\n"
        "    return rz @ ry @ rx"
    ],
    ("01", "span_word_ids"): [  # the last word started, also in the silence after it
        "def span_word_ids(words, n_frames, fps, vocab):\n    t = np.arange(n_frames) / fps\n"
        "    ids = np.array([vocab.get(w, 3) for w in words.words], dtype=np.int64)\n"
        "    k = np.searchsorted(words.starts, t, side='right') - 1\n"
        "    return np.where(k >= 0, ids[np.maximum(k, 0)], 0).astype(np.int64)",
        # the closed interval [start, end]; the word starting at t not yet counted; PAD for an unknown word
        _SPAN.format(side="right", unk=3, before="<="),
        _SPAN.format(side="left", unk=3, before="<"),
        _SPAN.format(side="right", unk=0, before="<"),
    ],
    ("01", "beat_decimate"): ["def beat_decimate(channels, ratio):\n    return channels[::ratio]"],  # phase 0
    ("01", "rodrigues"): [  # the sine term flipped (the inverse rotation); K of v, not of the unit axis
        "def rodrigues(rotvec):\n    v = np.asarray(rotvec, dtype=float)\n    theta = np.linalg.norm(v)\n"
        "    if theta < 1e-12:\n        return np.eye(3)\n    x, y, z = v / theta\n"
        "    K = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])\n"
        "    return np.eye(3) - np.sin(theta) * K + (1 - np.cos(theta)) * K @ K",
        "def rodrigues(rotvec):\n    x, y, z = np.asarray(rotvec, dtype=float)\n    theta = np.linalg.norm([x, y, z])\n"
        "    K = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])\n"
        "    return np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K",
    ],
    ("02", "joint_speed"): [  # cm per frame, not per second
        "def joint_speed(positions, fps):\n    p = np.asarray(positions, dtype=float)\n"
        "    if len(p) < 2:\n        return np.zeros(len(p))\n"
        "    v = np.linalg.norm(np.diff(p, axis=0), axis=2).mean(axis=1)\n    return np.concatenate([v[:1], v])"
    ],
    ("02", "eta_squared"): [  # group means not weighted by the group sizes
        "def eta_squared(values, labels):\n    x = np.asarray(values, dtype=float)\n"
        "    total = ((x - x.mean()) ** 2).sum()\n"
        "    return float(sum((x[labels == g].mean() - x.mean()) ** 2 for g in np.unique(labels)) / total)",
        # nan, not 0, when all values are equal
        "def eta_squared(values, labels):\n    x = np.asarray(values, dtype=float)\n    total = ((x - x.mean()) ** 2).sum()\n"
        "    between = sum((labels == g).sum() * (x[labels == g].mean() - x.mean()) ** 2 for g in np.unique(labels))\n"
        "    return float(between / total)",
    ],
    ("02", "window_stats"): [  # the sample standard deviation (ddof=1)
        "def window_stats(windows):\n    x = np.asarray(windows, dtype=float)\n"
        "    return np.concatenate([x.mean(axis=1), x.std(axis=1, ddof=1), np.abs(np.diff(x, axis=1)).mean(axis=1)], axis=1)"
    ],
    ("03", "mel_frames_per_window"): [  # the centred STFT's count (71 for a window, not 70)
        "def mel_frames_per_window(n_poses, fps, sr):\n    return int(np.floor(n_poses * sr / fps + 1e-9)) // 512 + 1"
    ],
    ("03", "nearest_words"): [  # the word itself left among its neighbours
        "def nearest_words(vectors, word_id, k):\n    v = vectors.astype(np.float64)\n"
        "    n = np.linalg.norm(v, axis=1, keepdims=True)\n    u = np.divide(v, n, out=np.zeros_like(v), where=n > 0)\n"
        "    sim = u @ u[word_id]\n    sim[:4] = -np.inf\n    return np.argsort(-sim, kind='stable')[:k]",
        # dot products of rows not normalised
        "def nearest_words(vectors, word_id, k):\n    v = vectors.astype(np.float64)\n    sim = v @ v[word_id]\n"
        "    sim[:4] = -np.inf\n    sim[word_id] = -np.inf\n    return np.argsort(-sim, kind='stable')[:k]",
        # the special tokens left among the neighbours
        "def nearest_words(vectors, word_id, k):\n    v = vectors.astype(np.float64)\n"
        "    n = np.linalg.norm(v, axis=1, keepdims=True)\n    u = np.divide(v, n, out=np.zeros_like(v), where=n > 0)\n"
        "    sim = u @ u[word_id]\n    sim[word_id] = -np.inf\n    return np.argsort(-sim, kind='stable')[:k]",
    ],
    ("03", "window_audio_span"): [  # rounded instead of floored
        "def window_audio_span(i, stride, length, fps, sr):\n    start = int(round(i * stride * sr / fps))\n"
        "    return start, start + int(round(length * sr / fps))"
    ],
    ("04", "frechet_1d"): [  # variances where the standard deviations belong
        "def frechet_1d(m1, s1, m2, s2):\n    return (m1 - m2) ** 2 + abs(s1**2 - s2**2)"
    ],
    ("04", "my_pck"): [  # per coordinate instead of the joint's distance
        "def my_pck(generated, ground_truth, delta):\n    return float(np.mean(np.abs(generated - ground_truth) < delta))"
    ],
    ("04", "alignment"): [  # sigma^2 where 2 sigma^2 belongs
        "def alignment(query, reference, sigma):\n"
        "    d = np.abs(np.asarray(query)[:, None] - np.asarray(reference)[None, :]).min(axis=1)\n"
        "    return float(np.mean(np.exp(-(d**2) / sigma**2)))"
    ],
    ("05", "conv_out_length"): [  # the padding forgotten
        "def conv_out_length(n, kernel, stride, padding):\n    return (n - kernel) // stride + 1"
    ],
    ("05", "samples_for_35"): [  # issue 27: 36266 (34 frames), 33500, and 36266 + one frame of 1080 samples
        "samples_for_35 = 36266",
        "samples_for_35 = 33500",
        "samples_for_35 = 36266 + 1080",
    ],
    ("05", "semantic_huber"): [  # the semantic weights left out
        "def semantic_huber(pred, target, semantic, beta=0.1):\n    d = np.abs(pred - target)\n"
        "    return float(np.mean(np.where(d < beta, 0.5 * d**2 / beta, d - 0.5 * beta)))"
    ],
    ("05", "make_pre_seq"): [  # the indicator bit left at 0
        "def make_pre_seq(pose, n_pre=4):\n    b, t, d = pose.shape\n"
        "    out = np.zeros((b, t, d + 1), dtype=pose.dtype)\n    out[:, :n_pre, :d] = pose[:, :n_pre]\n    return out"
    ],
    ("05", "why_bit"): ["why_bit = 'a'", "why_bit = 'c'"],
    ("06", "blend"): [  # the three levels averaged, the weights ignored
        "def blend(f_low, f_mid, f_high, weights):\n    s = np.stack([f_low, f_mid, f_high], axis=1)\n"
        "    return np.repeat(s.mean(axis=1, keepdims=True), weights.shape[2], axis=1)"
    ],
    ("06", "unit_directions"): [  # child -> parent
        "def unit_directions(positions, bones):\n    v = positions[:, bones[:, 0]] - positions[:, bones[:, 1]]\n"
        "    return v / np.linalg.norm(v, axis=-1, keepdims=True)"
    ],
    ("06", "physical_loss"): [  # averaged over the pairs instead of summed
        "def physical_loss(angles, mean, var):\n    return float(((angles - mean) ** 2 / (2 * var)).mean())"
    ],
    ("06", "costliest"): [  # every other option (the answer depends on the data)
        "costliest = [k for k in pair_options if bl.exercise.course_key('costliest pair', k) != pair_key][0]",
        "costliest = [k for k in pair_options if bl.exercise.course_key('costliest pair', k) != pair_key][-1]",
    ],
    ("07", "kendall_tau"): [  # ordered pairs in the denominator (half the value)
        "def kendall_tau(a, b):\n    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)\n"
        "    s = np.sign(a[:, None] - a[None]) * np.sign(b[:, None] - b[None])\n    return float(s.sum() / 2 / len(a) ** 2)"
    ],
    ("07", "per_class_accuracy"): [  # precision, not recall
        "def per_class_accuracy(predicted, labels):\n"
        "    return np.array([np.mean(labels[predicted == c] == c) if np.any(predicted == c) else 0.0 for c in np.unique(labels)])",
        # the classes of the predictions, not of the labels
        "def per_class_accuracy(predicted, labels):\n"
        "    return np.array([np.mean(predicted[labels == c] == c) for c in np.unique(predicted)])",
    ],
    ("08", "speed_minima"): [  # frame indices, not seconds
        "def speed_minima(positions, fps):\n    speed = np.linalg.norm(np.gradient(positions, 1 / fps, axis=0), axis=-1)\n"
        "    n = len(speed)\n    idx = np.arange(n)\n    keep = np.ones(n, dtype=bool)\n    for k in (1, 2):\n"
        "        keep &= speed < speed[np.minimum(idx + k, n - 1)]\n        keep &= speed < speed[np.maximum(idx - k, 0)]\n"
        "    return np.flatnonzero(keep).astype(float)"
    ],
    ("08", "face_at_rate"): [  # BEAT's motion phase (notebook 01) used for the face
        "def face_at_rate(weights, face_fps, fps):\n    return weights[1 :: int(round(face_fps / fps))]"
    ],
    ("09", "bt_update"): [  # not normalised to sum 1
        "def bt_update(p, wins):\n    wins = np.asarray(wins, dtype=float)\n    n = wins + wins.T\n"
        "    total = np.array([sum(n[i, j] / (p[i] + p[j]) for j in range(len(p)) if j != i) for i in range(len(p))])\n"
        "    return wins.sum(axis=1) / total"
    ],
    ("09", "left_out"): ["left_out = 0.5", "left_out = 1 / K", "left_out = 1 / np.e"],  # 1/e: K large, not 8
    ("09", "take_interval"): [  # a 90 % interval
        "def take_interval(per_take, n, seed):\n    rng = np.random.default_rng(seed)\n    x = np.asarray(per_take, dtype=float)\n"
        "    means = [x[rng.integers(len(x), size=len(x))].mean() for _ in range(n)]\n    return np.percentile(means, [5, 95])"
    ],
    ("10", "ddim_step"): [  # the re-noising term left out (the clean estimate, only rescaled)
        "def ddim_step(x_t, eps, t, prev):\n    a_t, a_p = float(schedule.alpha_bars[t]), float(schedule.alpha_bars[prev])\n"
        "    return np.sqrt(a_p) * (x_t - np.sqrt(1 - a_t) * eps) / np.sqrt(a_t)",
        # the one-step alphas of t and prev where their products belong
        "def ddim_step(x_t, eps, t, prev):\n    a_t, a_p = float(schedule.alphas[t]), float(schedule.alphas[prev])\n"
        "    x0 = (x_t - np.sqrt(1 - a_t) * eps) / np.sqrt(a_t)\n    return np.sqrt(a_p) * x0 + np.sqrt(1 - a_p) * eps",
    ],
    ("10", "snr_at"): [  # alpha_t / beta_t: one step's ratio, not the product's
        "def snr_at(steps, beta_1, beta_T, t):\n    b = np.linspace(beta_1, beta_T, steps)[t - 1]\n    return float((1 - b) / b)",
        # the amplitude ratio sqrt(abar / (1 - abar))
        "def snr_at(steps, beta_1, beta_T, t):\n    ab = np.prod(1 - np.linspace(beta_1, beta_T, steps)[:t])\n"
        "    return float(np.sqrt(ab / (1 - ab)))",
    ],
}


#: (notebook number, the student's name) -> right answers written otherwise than the solution, which must pass.
RIGHT: dict[tuple[str, str], list[str]] = {
    ("02", "window_stats"): [  # no cast to float64 (the windows are float32)
        "def window_stats(windows):\n    return np.concatenate([windows.mean(axis=1), windows.std(axis=1), "
        "np.abs(np.diff(windows, axis=1)).mean(axis=1)], axis=1)"
    ],
    ("04", "my_pck"): [  # changes its input in place (check gives each function its own copy)
        "def my_pck(generated, ground_truth, delta):\n    generated -= ground_truth\n"
        "    return float(np.mean(np.linalg.norm(generated, axis=-1) < delta))"
    ],
    ("07", "per_class_accuracy"): [  # a list, not an array (the lines after the check took its .mean())
        "def per_class_accuracy(predicted, labels):\n"
        "    return [float(np.mean(predicted[labels == c] == c)) for c in sorted(set(labels.tolist()))]"
    ],
    ("08", "speed_minima"): [  # np.gradient over the frame times instead of a spacing
        "def speed_minima(positions, fps):\n    t = np.arange(len(positions)) / fps\n"
        "    speed = np.linalg.norm(np.gradient(positions, t, axis=0), axis=-1)\n"
        "    n = len(speed)\n    idx = np.arange(n)\n    keep = np.ones(n, dtype=bool)\n    for k in (1, 2):\n"
        "        keep &= speed < speed[np.minimum(idx + k, n - 1)]\n        keep &= speed < speed[np.maximum(idx - k, 0)]\n"
        "    return np.flatnonzero(keep) / fps"
    ],
    # in torch, vectorised: the cell after the check called p.round(4), numpy's signature, on the tensor
    ("09", "bt_update"): [
        "def bt_update(p, wins):\n    import torch\n    w = torch.as_tensor(np.asarray(wins), dtype=torch.float64)\n"
        "    p = torch.as_tensor(p, dtype=torch.float64)\n    d = (w + w.T) / (p[:, None] + p[None, :])\n"
        "    new = w.sum(1) / (d.sum(1) - d.diagonal())\n    return new / new.sum()"
    ],
    # in torch's default float32, where 1 - abar_1 = 1e-4 is off by 1.7e-4 of itself: SNR(1) = 9997.3, not 9999
    ("10", "snr_at"): [
        "def snr_at(steps, beta_1, beta_T, t):\n    abar = torch.cumprod(1 - torch.linspace(beta_1, beta_T, steps), 0)[t - 1]\n"
        "    return float(abar / (1 - abar))"
    ],
}


def _all_exercises():
    return [(path, ex) for path in NOTEBOOKS for ex in sheet.exercises(path)]


# ----------------------------------------------------------------------------- static checks (fast)
def test_float32_results_match_within_their_rounding_and_no_further():
    """notebook 06's ``blend`` solution (numpy einsum) and its reference (torch) summed float32 products in another
    order: 2 of 3264 elements near zero differed by 2.2e-8 (-0.000459671 vs -0.000459649, the largest value about
    0.36), beyond numpy.isclose's atol of 1e-8: the right solution was rejected in one of two fresh-clone runs."""
    import numpy as np

    from beatlite.exercise import difference

    want = np.array([0.36, -4.59649e-4], np.float32)
    got = want.copy()
    got[1] = np.float32(-4.59671e-4)
    assert difference(got, want) is None  # 2.2e-8 < 16 * 1.19e-7 * 0.36 = 6.9e-7
    assert (
        difference(got.astype(np.float64), want.astype(np.float64)) is not None
    )  # float64: numpy's tolerance
    got[1] = np.float32(-4.59649e-4 + 2e-6)  # beyond float32 rounding at this scale
    assert difference(got, want) is not None
    assert difference(want * np.float32(1.001), want) is not None  # a real (0.1 %) difference still counts


def test_every_notebook_has_exercises_with_solutions():
    found = _all_exercises()
    assert {p.name for p, _ in found} == {p.name for p in NOTEBOOKS}
    assert len(found) == 31 and sum(len(ex.calls) for _, ex in found) == 34  # counted in the notebooks
    for path, ex in found:
        assert ex.stubs and ex.solutions, f"{path.name} {ex.title}: needs a stub cell and a solution cell"
        assert ex.names, f"{path.name} {ex.title}: no stub (raise NotImplementedError / answer = None)"
        solution = "\n".join(src for _, src in ex.solutions)
        defined = {
            n.name if isinstance(n, ast.FunctionDef) else t.id
            for n in ast.parse(sheet._python(solution)).body
            if isinstance(n, ast.FunctionDef | ast.Assign)
            for t in (n.targets if isinstance(n, ast.Assign) else [n])
            if isinstance(n, ast.FunctionDef) or isinstance(t, ast.Name)
        }
        assert set(ex.names) <= defined, f"{path.name} {ex.title}: the solution sets {sorted(defined)}"
        called = {name for _, name, _ in sheet.exercise_calls(solution)}
        assert called == {name for _, name, _ in ex.calls}, (
            f"{path.name} {ex.title}: the solution re-runs every check"
        )


def test_every_exercise_has_a_wrong_answer():
    needed = {(path.name[:2], name) for path, ex in _all_exercises() for name in ex.names}
    assert needed == set(WRONG), (
        f"missing wrong answers: {sorted(needed - set(WRONG))}, stale: {sorted(set(WRONG) - needed)}"
    )
    assert set(RIGHT) <= needed, f"right answers of no exercise: {sorted(set(RIGHT) - needed)}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_no_student_cell_makes_a_choice_key(path):
    """A key made in the student's cell shows the answer it is made from (notebook 06, issue 27)."""
    nb = json.loads(path.read_text(encoding="utf-8"))
    for i, cell in enumerate(nb["cells"]):
        if cell["cell_type"] != "code" or "solution" in cell.get("metadata", {}).get("tags", []):
            continue
        src = "".join(cell["source"])
        assert "answer_key(" not in src and "course_key(" not in src, f"{path.name} cell {i} makes a key"


def _library_calls(func: ast.FunctionDef) -> set[str]:
    """What ``func`` calls outside numpy, the builtins and the names it assigns (a method of a parameter counts,
    e.g. ``index.where``)."""
    own = {
        t.id
        for n in ast.walk(func)
        if isinstance(n, ast.Assign)
        for t in n.targets
        if isinstance(t, ast.Name)
    }
    calls = set()
    for node in ast.walk(func):
        if isinstance(node, ast.Call):
            root = node.func
            while isinstance(root, ast.Attribute | ast.Subscript | ast.Call):
                root = root.value if not isinstance(root, ast.Call) else root.func
            if (
                isinstance(root, ast.Name)
                and root.id not in own | {"np", "numpy"}
                and root.id not in dir(builtins)
            ):
                calls.add(ast.unparse(node.func))
    return calls


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_no_stub_cell_shows_the_answer(path):
    """The reference beside a stub (the cell the student fills in) calls the library, torch, scipy...: one written
    out in numpy alone is the answer in plain sight (notebook 09's bootstrap was, line for line)."""
    for ex in sheet.exercises(path):
        for _, src in ex.stubs:
            for node in ast.parse(sheet._python(src)).body:
                if isinstance(node, ast.FunctionDef) and node.name not in ex.names:
                    assert _library_calls(node), (
                        f"{path.name} {ex.title}: {node.name} in the student's cell is written out in numpy; "
                        "call the library's reference instead"
                    )


def test_instructor_sheet_has_every_answer(tmp_path):
    written = sheet.write_sheets(tmp_path)
    assert written[0] == tmp_path / "answers.md" and len(written) == 1 + len(NOTEBOOKS)
    text = (tmp_path / "05_camn.md").read_text()
    assert 'predict "audio for 35 frames": predicted value `samples_for_35 = n35`' in text
    assert "choice \"indicator bit\": right choice `why_bit = 'b'`" in text
    assert "n >= 36545" in text  # the written answer of the prediction
    assert "Answer (why): each pair costs about 0.5" in (tmp_path / "06_ha2g.md").read_text()
    assert "left_out = (1 - 1 / K) ** K" in (tmp_path / "09_scoring.md").read_text()
    answers = (tmp_path / "answers.md").read_text()
    assert answers.count("\n## Exercise") == 31 and "no solution cell" not in answers


# ----------------------------------------------------------------------------- running the checks
def _free_names(src: str) -> set[str]:
    """Names a cell reads that it does not itself define (a store anywhere in the cell counts; a function's
    parameters count inside that function only)."""

    def loads(node: ast.AST, local: frozenset[str]) -> set[str]:
        if isinstance(node, ast.FunctionDef | ast.Lambda):
            args = node.args
            names = {a.arg for a in args.posonlyargs + args.args + args.kwonlyargs}
            names |= {a.arg for a in (args.vararg, args.kwarg) if a is not None}
            local = local | names
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Load) and node.id not in local:
            return {node.id}
        return set().union(*(loads(child, local) for child in ast.iter_child_nodes(node)))

    return loads(ast.parse(sheet._python(src)), frozenset()) - _stores(src) - set(dir(builtins))


def _stores(src: str) -> set[str]:
    out = set()
    for node in ast.walk(ast.parse(sheet._python(src))):
        if isinstance(node, ast.Name) and not isinstance(node.ctx, ast.Load):
            out.add(node.id)
        elif isinstance(node, ast.FunctionDef | ast.ClassDef):
            out.add(node.name)
        elif isinstance(node, ast.alias):
            out.add((node.asname or node.name).split(".")[0])
    return out


def _setup_cells(cells: list[dict], first: int, needed: set[str]) -> list[int]:
    """The code cells before ``first`` (not ``check``, not ``solution``) that define ``needed``, transitively,
    and the first code cell after the Colab cell (imports and ``notebook.setup``)."""
    chosen = []
    code = [
        i
        for i in range(first)
        if cells[i]["cell_type"] == "code" and "colab" not in cells[i].get("metadata", {}).get("tags", [])
    ]
    for i in reversed(code):
        tags = cells[i].get("metadata", {}).get("tags", [])
        if {"check", "solution"} & set(tags):
            continue
        src = "".join(cells[i]["source"])
        if _stores(src) & needed or i == code[0]:
            chosen.append(i)
            needed = (needed - _stores(src)) | _free_names(src)
    return sorted(chosen)


def _without_stubs(src: str, names: list[str], *, whole: bool = False) -> str:
    """The stub cell without the student's part, up to its last exercise call (``whole``: to its end)."""
    tree = ast.parse(sheet._python(src))
    body = []
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name in names:
            continue
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id in names for t in node.targets
        ):
            continue
        body.append(node)
    last = (
        len(body) - 1
        if whole
        else max(i for i, node in enumerate(body) if sheet.exercise_calls(ast.unparse(node)))
    )
    return ast.unparse(ast.Module(body=body[: last + 1], type_ignores=[]))


def _follow_up(cells: list[dict], ex) -> list[int]:
    """The code cells between an exercise's first stub and its first solution that are not stubs: what the student
    runs next (a ``check`` cell, a cell that uses the answer through :func:`beatlite.exercise.resolve`)."""
    stubs = {i for i, _ in ex.stubs}
    return [
        i
        for i in range(min(stubs), min(i for i, _ in ex.solutions))
        if cells[i]["cell_type"] == "code" and i not in stubs
    ]


def _run(path: Path, tmp: Path) -> list[tuple[str, str, str, object]]:
    """Run a notebook's exercises as the module docstring says: rows ``(exercise, step, check name, result)``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from beatlite import exercise

    nb = json.loads(path.read_text(encoding="utf-8"))
    cells = nb["cells"]
    found = sheet.exercises(path)
    every = [src for ex in found for _, src in ex.stubs + ex.solutions]
    every += ["".join(cells[i]["source"]) for ex in found for i in _follow_up(cells, ex)]
    every += [w for ex in found for n in ex.names for w in WRONG.get((path.name[:2], n), [])]
    every += [r for ex in found for n in ex.names for r in RIGHT.get((path.name[:2], n), [])]
    needed = set().union(*(_free_names(src) for src in every))
    setup = _setup_cells(cells, min(i for ex in found for i, _ in ex.stubs), needed)

    rows: list[tuple[str, str, str, object]] = []
    step = {"exercise": "", "step": ""}
    originals = {name: getattr(exercise, name) for name in sheet.CALLS}

    def recorder(fn):
        def call(name, *args, **kwargs):
            result = fn(name, *args, **kwargs)
            rows.append((step["exercise"], step["step"], name, result))
            return result

        return call

    env = {"BEATLITE_BUILD": str(tmp), "BEATLITE_INTERACTIVE": "off", "MPLBACKEND": "Agg"}
    saved_env = {k: os.environ.get(k) for k in env}
    cwd = Path.cwd()
    ns: dict = {"__name__": "__main__"}
    try:
        os.environ.update(env)
        os.chdir(path.parent)
        for name in sheet.CALLS:
            setattr(exercise, name, recorder(originals[name]))
        for i in setup:
            exec(compile(sheet._python("".join(cells[i]["source"])), f"{path.name}[{i}]", "exec"), ns)
        for ex in found:
            step["exercise"] = ex.title
            step["step"] = "stub"
            for i, src in ex.stubs:
                exec(compile(sheet._python(src), f"{path.name}[{i}]", "exec"), ns)
            for name in ex.names:
                answers = [("wrong", w) for w in WRONG[path.name[:2], name]]
                answers += [("right", r) for r in RIGHT.get((path.name[:2], name), [])]
                for k, (kind, answer) in enumerate(answers):
                    step["step"] = f"{kind} {name} #{k + 1}"
                    exec(answer, ns)
                    for i, src in ex.stubs:
                        if name in sheet.student_names(src):
                            code = _without_stubs(src, [name], whole=kind == "right")
                            exec(compile(code, f"{path.name}[{i}]", "exec"), ns)
                    if kind == "right":
                        for i in _follow_up(cells, ex):
                            code = sheet._python("".join(cells[i]["source"]))
                            exec(compile(code, f"{path.name}[{i}]", "exec"), ns)
            step["step"] = "solution"
            for i, src in ex.solutions:
                exec(compile(sheet._python(src), f"{path.name}[{i}]", "exec"), ns)
    finally:
        for name, fn in originals.items():
            setattr(exercise, name, fn)
        os.chdir(cwd)
        for k, v in saved_env.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
        plt.close("all")
    return rows


def _answer_of(ex, name: str) -> set[str]:
    """The checks whose answer is ``name`` (a check's student function, a choice's or prediction's variable)."""
    return {call for _, call, arg in ex.calls if arg is not None and ast.unparse(arg) == name}


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_exercises_accept_the_solution_and_reject_wrong_answers(path, tmp_path):
    rows = _run(path, tmp_path)
    for ex in sheet.exercises(path):
        mine = [r for r in rows if r[0] == ex.title]
        calls = {name for _, name, _ in ex.calls}
        stub = {(name, result) for _, step, name, result in mine if step == "stub"}
        assert stub == {(name, None) for name in calls}, f"{ex.title}: the stub is not 'not done yet': {stub}"
        solved = {(name, result) for _, step, name, result in mine if step == "solution"}
        assert solved == {(name, True) for name in calls}, f"{ex.title}: the solution does not pass: {solved}"
        for name in ex.names:
            for k in range(len(WRONG[path.name[:2], name])):
                got = [(c, r) for _, step, c, r in mine if step == f"wrong {name} #{k + 1}"]
                assert got and {c for c, _ in got} == _answer_of(ex, name), (
                    f"{ex.title}: {name} #{k + 1}: {got}"
                )
                assert all(r is False for _, r in got), (
                    f"{ex.title}: wrong {name} #{k + 1} was accepted: {got}"
                )
            n_wrong = len(WRONG[path.name[:2], name])
            for k in range(len(RIGHT.get((path.name[:2], name), []))):
                got = [(c, r) for _, step, c, r in mine if step == f"right {name} #{n_wrong + k + 1}"]
                assert got and {c for c, _ in got} == _answer_of(ex, name), (
                    f"{ex.title}: right {name} #{k + 1}: {got}"
                )
                assert all(r is True for _, r in got), f"{ex.title}: right {name} #{k + 1} refused: {got}"
