"""The docs stay a product's docs: at most 1,600 lines in docs/ besides RELATIONS.md (RESULTS at most 350; the lab
notebook lives in git history and experiments/), the learned relational route's own page at most 140, and the test
set is called what it is: no longer held out, with the choices that read it."""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS_BUDGET, RESULTS_BUDGET, RELATIONS_BUDGET = 1600, 350, 140
# the choices made after reading problems/test's results (docs/RESULTS.md, "What looked at the test set")
TEST_SET_CHOICES = ("min_count", "vacant", "rests", "keep_plan_on_failed_replan")


def line_count(path: Path) -> int:
    return len(path.read_text(encoding="utf-8").splitlines())


def test_docs_fit_their_budget():
    sizes = {p.name: line_count(p) for p in sorted((ROOT / "docs").glob("*.md"))}
    assert sizes.pop("RELATIONS.md") <= RELATIONS_BUDGET
    assert sum(sizes.values()) <= DOCS_BUDGET, sizes
    assert sizes["RESULTS.md"] <= RESULTS_BUDGET, sizes["RESULTS.md"]


def held_out_claims(text: str) -> list[str]:
    """Sentences that call the planning test set held out without saying that it no longer is."""
    out = []
    for sentence in re.split(r"(?<=[.;:])\s+", " ".join(text.split())):
        if re.search(r"held[- ]out (test set|problems)|problems/test`?,? (a )?held[- ]out", sentence) \
                and "no longer" not in sentence:
            out.append(sentence)
    return out


def test_the_test_set_is_not_called_held_out():
    docs = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    assert {d.name: held_out_claims(d.read_text(encoding="utf-8")) for d in docs
            if held_out_claims(d.read_text(encoding="utf-8"))} == {}
    for name in ("README.md", "docs/RESULTS.md", "docs/PROBLEMS.md"):
        text = " ".join((ROOT / name).read_text(encoding="utf-8").split())
        assert "no longer held out" in text, name
        windows = [text[max(0, m.start() - 500):m.end() + 500] for m in re.finditer("no longer", text)]
        assert any(all(choice in w for choice in TEST_SET_CHOICES) for w in windows), name


def test_the_claim_check_finds_the_old_wording():
    assert held_out_claims("Planning is reported on `problems/test`, a held-out set. Results on the held-out test set.")
    assert not held_out_claims("`problems/test` is no longer held out: it was read. The test split was held out.")
