"""`symlearn export-pddl --rules`: distil a run's transition network into rules and a PDDL domain.

Steps: the vocabulary is every code the encoder gives a training object (before or after an
action), with counts, optionally closed under the network; every multiset scene of 1..K objects
over it times the 36 actions is enumerated in batched calls; the answers are distilled into
exact rules (pddl_export.rules); the conditional-effects domain is written; fidelity is measured
on every enumerated case through the rules, and on a seeded sample through the PDDL itself
(unified-planning's simulator, about 16 ms a case).

The second outcomes (pddl_export.outcome_rules) are distilled on the same scenes for the
`rules-outcomes` planner.

Writes RUN/pddl/domain.pddl, rules.json, outcomes.json, report.json.
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pddl_export.enumeration import enumerate_scenes, enumerate_transitions, vocabulary_closure
from pddl_export.distil import distil_rules
from pddl_export.fidelity import pddl_fidelity, rule_fidelity
from pddl_export.files import atomic_write_files, json_text, sha256_file
from pddl_export.outcome_rules import MIN_OUTCOME_RATIO, OUTCOMES_FILE, distil_outcomes, outcomes_to_json
from pddl_export.pddl_writer import conditional_domain
from pddl_export.rules_io import PDDL_DIR, RULES_FILE, rules_to_json
from pddl_export.symbolic import code_str
from symlearn.config_file import Bound, check_bounds
from symlearn.provenance import versions


@dataclass(frozen=True)
class ExportConfig:
    """How the network is enumerated and checked."""

    max_objects: int = 3  # largest enumerated scene: the rules are exact up to it
    min_count: int = 1  # a code enters the vocabulary once this many training objects have it
    closure: bool = False  # also add codes the network produces from enumerated scenes
    pddl_fidelity_cases: int = 500  # sampled cases simulated through the PDDL (0: none; -1: all)
    # "observed": the code multisets of training scenes (and their sub-multisets); "all": every multiset
    # of vocabulary codes. A learned network answers impossible scenes (three objects on one spot)
    # arbitrarily, and exact rules for those answers swell the domain (316k rules for 60 codes, K = 3).
    scenes: str = "observed"
    # observed: also enumerate the sub-multisets of up to max_objects codes of observed scenes with more
    # objects; with max_objects 4-5 the rules are exact on the bigger scenes of a 1-5-object set
    larger_scenes: bool = False
    seed: int = 0
    # outcomes.json: each object's second likeliest next code where it is at least this fraction as likely
    outcome_min_ratio: float = MIN_OUTCOME_RATIO

    def __post_init__(self) -> None:
        """Refuse what cannot be enumerated or sampled ([export] in a settings file)."""
        check_bounds(self, {"min_count": Bound(1, 2**62, integer=True), "seed": Bound(0, 2**63 - 1, integer=True),
                            "pddl_fidelity_cases": Bound(-1, 10_000_000, integer=True)})
        if not 1 <= self.max_objects <= 5:
            raise ValueError(f"max_objects={self.max_objects} must lie in 1..5")
        if not 0 < self.outcome_min_ratio <= 1:
            raise ValueError(f"outcome_min_ratio={self.outcome_min_ratio} must lie in (0, 1]")
        if self.scenes not in ("observed", "all"):
            raise ValueError(f"scenes={self.scenes!r}: expected observed or all")
        if self.larger_scenes and self.scenes != "observed":
            raise ValueError("larger_scenes takes sub-scenes of observed scenes: it needs scenes='observed'")



def training_codes(run_dir: Path, data_dir: Path, model=None) -> tuple[np.ndarray, np.ndarray]:
    """The codes of every training sample's objects before and after, as m(z) reads them: two (N, K), -1 padding.

    model: the run's effect model or SymbolReader when already loaded; else loaded from run_dir, with m(z)'s
    location bits once the run has a transition.pt.
    """
    from symlearn.data.dataset import load_split
    from symlearn.learning.checkpoint import load_effect_model
    from symlearn.symbolic.learned_transition import planning_models
    from symlearn.symbolic.symbols import encode_codes
    from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE

    if model is None:
        model = (planning_models(run_dir)[0] if (Path(run_dir) / TRANSITION_FILE).exists()
                 else load_effect_model(Path(run_dir))[0])
    data = load_split(data_dir, "train")
    return (encode_codes(model, data.pre_depth, data.pre_origin, data.mask),
            encode_codes(model, data.post_depth, data.post_origin, data.mask))


def code_counts(*code_arrays: np.ndarray) -> dict[int, int]:
    """Code -> number of object occurrences, most frequent first (padding -1 ignored)."""
    flat = np.concatenate([c[c >= 0] for c in code_arrays])
    uniq, n = np.unique(flat, return_counts=True)
    return {int(c): int(k) for c, k in sorted(zip(uniq, n), key=lambda t: -t[1])}


def observed_scenes(vocab: set[int], max_objects: int, *code_arrays: np.ndarray,
                    larger: bool = False) -> list[tuple[int, ...]]:
    """Distinct code multisets of observed scenes whose codes all lie in the vocabulary, and their sub-multisets.

    With `larger`, scenes of more than max_objects objects add their sub-multisets of up to max_objects
    codes that lie in the vocabulary.
    """
    from itertools import combinations

    out: set[tuple[int, ...]] = set()
    for arr in code_arrays:
        for row in np.unique(np.sort(arr, axis=1), axis=0):
            sc = tuple(int(c) for c in row if c >= 0)
            if not sc:
                continue
            if len(sc) <= max_objects and set(sc) <= vocab:
                for k in range(1, len(sc) + 1):
                    out.update(combinations(sc, k))
            elif larger and len(sc) > max_objects:
                known = tuple(c for c in sc if c in vocab)
                for k in range(1, min(len(known), max_objects) + 1):
                    out.update(combinations(known, k))
    return sorted(out)


def _export_outcomes(transition, enum, min_ratio: float, model_hash: str) -> tuple[dict, dict]:
    """Distil the second-outcome rules: what out/outcomes.json holds, and their summary for the report."""
    t0 = time.perf_counter()
    outcomes, alt_enum = distil_outcomes(transition, enum, min_ratio)
    fid = rule_fidelity(outcomes.rules, alt_enum)
    return ({"model_hash": model_hash, **outcomes_to_json(outcomes)},
            {"min_ratio": min_ratio, "n_rules": outcomes.rules.n_rules, "n_alternatives": len(outcomes.costs),
             "fidelity": round(fid.fraction, 6), "seconds": round(time.perf_counter() - t0, 1)})


def export_pddl(run_dir: Path, data_dir: Path, cfg: ExportConfig, out_dir: Path | None = None,
                extra_data: tuple[Path, ...] = ()) -> dict:
    """Enumerate, distil, write and check; returns the report (also written as report.json).

    extra_data: more data sets whose training codes join the vocabulary counts and the observed scenes
    (for instance 1-5-object sets the effect model never saw, as the further `--data` sets of `train-transition`).
    """
    from symlearn.data.dataset import data_fingerprint, data_records, distinct_extra_data
    from symlearn.symbolic.learned_transition import planning_models
    from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE

    run_dir = Path(run_dir)
    out = Path(out_dir) if out_dir else run_dir / PDDL_DIR
    reader, transition = planning_models(run_dir)
    model_hash = sha256_file(run_dir / TRANSITION_FILE)[:16]
    extra_data = distinct_extra_data(data_dir, extra_data)
    t0 = time.perf_counter()
    code_sets = [training_codes(run_dir, d, reader) for d in (data_dir, *extra_data)]
    arrays = [a for pair in code_sets for a in pair]
    counts = code_counts(*arrays)
    vocab = sorted(c for c, n in counts.items() if n >= cfg.min_count)
    if not vocab:
        raise ValueError(f"no code has --min-count {cfg.min_count} training objects in {data_dir} (the most "
                         f"frequent has {max(counts.values(), default=0)}); lower --min-count or collect more data")
    t_vocab = time.perf_counter() - t0
    added: list[int] = []
    if cfg.scenes == "observed":
        scenes = observed_scenes(set(vocab), cfg.max_objects, *arrays, larger=cfg.larger_scenes)
        enum = enumerate_scenes(transition, vocab, scenes, cfg.max_objects)
    elif cfg.closure:
        clo = vocabulary_closure(transition, vocab, cfg.max_objects)
        enum, added = clo.enumeration, list(clo.added)
    else:
        enum = enumerate_transitions(transition, vocab, cfg.max_objects)
    t1 = time.perf_counter()
    rules = distil_rules(enum)
    t_rules = time.perf_counter() - t1
    fid = rule_fidelity(rules, enum)
    t_fid = time.perf_counter() - t1 - t_rules
    domain = conditional_domain(rules, model_hash)
    outcomes, outcomes_report = _export_outcomes(transition, enum, cfg.outcome_min_ratio, model_hash)
    t2 = time.perf_counter()
    n_pddl = None if cfg.pddl_fidelity_cases < 0 else cfg.pddl_fidelity_cases
    pf = pddl_fidelity(domain, rules, enum, max_cases=n_pddl, seed=cfg.seed) if n_pddl != 0 else None
    t_pddl = time.perf_counter() - t2
    produced = set(int(c) for c in enum.produced_codes())
    report = {
        "run": str(run_dir), "model_hash": model_hash, "config": dataclasses.asdict(cfg),
        "data": str(data_dir), "data_fingerprint": data_fingerprint(data_dir),
        "extra_data": data_records(extra_data),
        "scenes": cfg.scenes, "n_enumerated_scenes": enum.n_scenes,
        "vocabulary_size": len(vocab), "vocabulary_counts": {code_str(c, rules.bits): counts.get(c, 0) for c in vocab},
        "closure_added": [code_str(c, rules.bits) for c in added],
        "codes_produced_outside_vocabulary": sorted(code_str(c, rules.bits) for c in produced - set(vocab) - set(added)),
        "n_enumerated_cases": enum.n_queries, "enumeration_queries_per_s": round(enum.queries_per_s, 1),
        "n_rules_before_generalization": rules.n_rules_before_generalization, "n_rules": rules.n_rules,
        "n_actions_with_rules": len(rules.actions),
        "fidelity": round(fid.fraction, 6), "fidelity_object_codes": round(fid.n_object_codes_exact / max(fid.n_object_codes, 1), 6),
        "disagreements": [dataclasses.asdict(m) for m in fid.mismatches],
        "pddl_fidelity": None if pf is None else round(pf.fraction, 6),
        "pddl_fidelity_cases": None if pf is None else pf.n_cases,
        "pddl_disagreements": [] if pf is None else [m.as_row() for m in pf.disagreements],
        "outcomes": outcomes_report,
        "seconds": {"vocabulary": round(t_vocab, 1), "enumeration": round(enum.seconds, 1), "rules": round(t_rules, 1),
                    "rule_fidelity": round(t_fid, 1), "pddl_fidelity": round(t_pddl, 1)},
        "versions": versions(),
    }
    # the domain, the rules, their outcomes and the report replaced as one unit: a failed write leaves the old ones
    rules_json = json_text({"model_hash": model_hash, **rules_to_json(rules)})
    atomic_write_files({out / "domain.pddl": domain, out / RULES_FILE: rules_json,
                        out / OUTCOMES_FILE: json_text(outcomes), out / "report.json": json_text(report)})
    return report
