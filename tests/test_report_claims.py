"""Tests of beatlite.report.claim / claim_close and the generated row descriptions (numpy only, fast):
a sentence rendered from the seed record follows the record, so an edited record cannot leave it stale."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from beatlite.paths import checkpoints_dir
from beatlite.report import VERDICTS, claim, claim_close, claims
from beatlite.train.seeds import SeedResults, compare_rows


def _record() -> SeedResults:
    return SeedResults(
        {
            "Ground truth": {"FGD": [0.0], "BeatAlign": [0.93], "Diversity": [27.0]},
            "A": {"FGD": [3.0, 3.4, 3.2], "BeatAlign": [0.93, 0.935, 0.932], "Diversity": [20.0, 21.0, 22.0]},
            "B": {"FGD": [4.0, 4.6, 4.3], "BeatAlign": [0.92, 0.925, 0.922], "Diversity": [20.0, 21.0, 22.0]},
            "Text only": {
                "FGD": [9.0, 11.0, 10.0],
                "BeatAlign": [0.64, 0.66, 0.65],
                "Diversity": [1.0, 2.0, 3.0],
            },
        },
        [2021, 2022, 2023],
        {},
    )


def _recorded() -> SeedResults:
    from beatlite.train.seeds import recorded_seed_results

    path = checkpoints_dir() / "results_seeds.json"
    if not path.is_file():
        pytest.skip("no recorded seed table (make seeds)")
    return recorded_seed_results(path)


# ----------------------------------------------------------------------------- claim


def test_claim_direction_follows_the_metric():
    """FGD: lower is better; BeatAlign: higher is better; the sentence says which."""
    record = _record()
    fgd = claim(record, "A", "B", "FGD")
    assert fgd.verdict == "better" and not fgd.higher_is_better and fgd.delta == pytest.approx(-1.1)
    assert str(fgd).startswith("A is better than B on FGD (lower is better) by 1.10 ± ")
    assert claim(record, "B", "A", "FGD").verdict == "worse"
    beat = claim(record, "A", "B", "BeatAlign")
    assert beat.verdict == "better" and beat.higher_is_better
    assert "(higher is better)" in str(beat)


def test_claim_se_is_welch_and_a_ground_truth_row_adds_no_variance():
    record = _record()
    c = claim(record, "A", "B", "FGD")
    _, se = record.difference("A", "B", "FGD")
    assert c.se == pytest.approx(se) and c.seeds == (3, 3)
    gt = claim(record, "B", "Ground truth", "FGD")  # recorded once: not a draw
    assert gt.se == pytest.approx(np.std([4.0, 4.6, 4.3], ddof=1) / math.sqrt(3))
    assert gt.verdict == "worse" and gt.seeds == (3, 1) and "0.00 (one value)" in str(gt)


def test_claim_verdict_is_compare_rows_verdict_on_the_shipped_record():
    """One rule for the tables (compare_rows) and the sentences (claim), wherever compare_rows decides."""
    record = _recorded()
    rows = [r for r in record.values if len(record.values[r]["FGD"]) > 1]
    for metric in ("FGD", "SRGR", "BeatAlign", "BC"):
        for e in compare_rows(
            record, "CaMN", [r for r in rows if metric in record.values[r]], metrics=(metric,)
        ):
            c = claim(record, e.variant, "CaMN", metric)
            expected = {"noise": "indistinguishable"}.get(e.verdict, e.verdict)
            if e.variant == "CaMN":
                expected = "indistinguishable"  # delta 0, se > 0
            assert c.verdict == expected, (e, c)
            assert c.delta == pytest.approx(e.delta, nan_ok=True)


def test_claim_renders_the_opposite_when_the_record_is_edited_to_contradict_it():
    """The notebook 05 sentence: without text, BeatAlign is better than the full CaMN (+0.0068, 3.3 SE)."""
    record = _recorded()
    before = claim(record, "CaMN w/o text", "CaMN", "BeatAlign")
    assert before.verdict == "better" and str(before).startswith(
        "CaMN w/o text is better than CaMN on BeatAlign"
    )
    edited = copy.deepcopy(record)
    full = np.asarray(edited.values["CaMN"]["BeatAlign"])
    edited.values["CaMN w/o text"]["BeatAlign"] = list(full - 0.02)  # now clearly below the full model
    after = claim(edited, "CaMN w/o text", "CaMN", "BeatAlign")
    assert after.verdict == "worse" and str(after).startswith("CaMN w/o text is worse than CaMN on BeatAlign")
    edited.values["CaMN w/o text"]["BeatAlign"] = list(full + [0.002, -0.002, 0.0])  # no difference
    same = claim(edited, "CaMN w/o text", "CaMN", "BeatAlign")
    assert same.verdict == "indistinguishable" and "covers 0" in str(same) and "better" not in str(same)


def test_claim_edge_cases():
    record = _record()
    with pytest.raises(ValueError, match="descriptive|one of"):
        claim(record, "A", "B", "Speed")  # not a metric key
    with pytest.raises(KeyError):
        claim(record, "A", "Nobody", "FGD")
    one = SeedResults({"A": {"FGD": [3.0, math.nan]}, "B": {"FGD": [4.0, 5.0]}}, [1, 2], {})
    unknown = claim(one, "A", "B", "FGD")  # one finite seed of a per-seed row: no standard error
    assert unknown.verdict == "unknown" and "no standard error" in str(unknown)
    assert {c.verdict for c in claims(record, [("A", "B"), ("A", "B"), ("A", "Z")], "FGD")} <= set(VERDICTS)
    assert len(claims(record, [("A", "B"), ("A", "Z")], "FGD")) == 1


def test_claim_close_follows_the_record():
    """Notebook 07: which models' BeatAlign is close to the ground truth's; an edit moves a row between groups."""
    record = _record()
    close = claim_close(record, ["A", "B", "Text only", "Absent"], "Ground truth", "BeatAlign", within=0.05)
    assert list(close.near) == ["A", "B"] and list(close.far) == ["Text only"]
    assert "further: Text only (0.650)" in str(close)
    edited = copy.deepcopy(record)
    edited.values["Text only"]["BeatAlign"] = [0.92, 0.93, 0.94]
    assert not claim_close(edited, ["A", "B", "Text only"], "Ground truth", "BeatAlign", within=0.05).far


def test_claim_close_on_the_shipped_record_names_seq2seq_and_joint_embedding():
    record = _recorded()
    moving = [
        "Random clip",
        "Seq2Seq-style",
        "S2G-style",
        "A2G-style",
        "Joint Embedding-style",
        "Trimodal-style",
    ]
    close = claim_close(record, [*moving, "CaMN", "HA2G"], "Ground truth", "BeatAlign", within=0.05)
    assert set(close.far) == {"Seq2Seq-style", "Joint Embedding-style"}, close


# ----------------------------------------------------------------------------- row descriptions


def test_row_descriptions_come_from_the_registries():
    from beatlite.train.recipes import RECIPES, describe_row, describe_rows

    for name, recipe in RECIPES.items():
        line = describe_row(name)
        assert line.startswith(f"**{recipe.label}** (`{name}`): "), line
        for row in recipe.paper_rows:
            if row.row is not None:
                assert f'{row.paper} {row.table} "{row.row}"' in line, (name, line)
    assert "Reads: no speech input." in describe_row("mean_pose")
    assert "Reads: text." in describe_row("seq2seq_tiny")
    assert "audio" not in describe_row("camn_tiny_no_audio").split("Reads:")[1].split(".")[0]
    assert describe_rows(["s2g_tiny", "a2g_tiny"]).count("\n- ") == 1


def test_claim_against_the_ground_truth_says_above_or_below_where_the_data_is_the_target():
    """BC above the ground truth's is not "better": the sentence says above; FGD against it stays better/worse."""
    record = _record()
    record.values["Ground truth"]["BC"], record.values["A"]["BC"] = [0.66], [0.77, 0.78, 0.76]
    above = claim(record, "A", "Ground truth", "BC")
    assert above.verdict == "better" and above.against_data
    assert str(above).startswith("A is above Ground truth on BC by 0.110 ± ")
    record.values["A"]["BC"] = [0.55, 0.56, 0.54]
    assert str(claim(record, "A", "Ground truth", "BC")).startswith("A is below Ground truth on BC")
    fgd = claim(record, "A", "Ground truth", "FGD")  # FGD 0 is perfect: worse is worse
    assert not fgd.against_data and str(fgd).startswith("A is worse than Ground truth on FGD")


def test_the_notebooks_table6_sentences_follow_the_papers_table():
    """Notebooks 02 and 07 say the paper's Table 6 "avg." is not the mean of its per-class accuracies: the means,
    computed here from ``PAPER_TABLE6``, are the numbers they quote."""
    import json

    from beatlite.paths import repo_root
    from beatlite.stats import PAPER_TABLE6

    mean = {k: np.mean([x for c, x in v.items() if c != "avg"]) for k, v in PAPER_TABLE6.items()}
    assert abs(mean["real"] - PAPER_TABLE6["real"]["avg"]) > 1.0  # not the mean (the human row is)
    text = {
        nb: "".join(
            "".join(c["source"]) for c in json.loads((repo_root() / "notebooks" / nb).read_text())["cells"]
        )
        for nb in ("02_dataset_statistics.ipynb", "07_benchmark.ipynb")
    }
    real, generated = f"{mean['real']:.1f} %", f"{mean['generated']:.1f} %"
    assert (
        f"{PAPER_TABLE6['real']['avg']:.2f} %" in text["07_benchmark.ipynb"]
        and real in text["07_benchmark.ipynb"]
    )
    assert (
        generated in text["07_benchmark.ipynb"]
        and f"{PAPER_TABLE6['generated']['avg']:.2f} %" in text["07_benchmark.ipynb"]
    )
    assert f"its per-class mean: {real}" in text["02_dataset_statistics.ipynb"]
