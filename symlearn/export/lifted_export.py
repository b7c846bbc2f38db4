"""`symlearn export-pddl`: the lifted domain of a run's codes, distilled from its training moves.

Every training scene of the given data sets (each state as the robot saw it, in the run's located codes, with the
action it took) is read as a move of pieces (pddl_export.lifted_rules), with its outcome: what the robot observed
next (LiftedConfig.source "observed", the default) or m(z)'s likeliest answer ("network"); the moves are
distilled into lifted rules, whose shares and alternatives are m(z)'s answers. They are checked on the sets'
held-out test splits: against m(z)'s own likeliest step (fidelity) and against what the robot observed next
(accuracy, beside m(z)'s own), whole scenes compared on what the domain states (kept learned bits, location,
place, level).

Needs an m(z) on 9 location bits (`train-transition --preset recommended`, its default): location, place and
level are the relations of the domain. Writes RUN/pddl/lifted.json (the rules, the layout, the type reader, the
checks) and RUN/pddl/lifted/domain.pddl.
"""
from __future__ import annotations

import dataclasses
import time
from collections import Counter
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Iterator, Sequence

import numpy as np

from pddl_export.end_moves import distil_end_rules
from pddl_export.files import atomic_write_files, atomic_write_folder, json_text, sha256_file
from pddl_export.lifted_distil import MIN_GAIN, POOL_MIN_COUNT, POOL_STRUCTURE_MIN, distil_lifted, with_network_answers
from pddl_export.lifted_domain import domain_pddl, schemas
from pddl_export.lifted_rules import POOLED_CLASSES, LiftedRules, build_codebook, observed_end_moves, observed_moves, \
    participants, stick_reader
from pddl_export.lifted_scene import CodeLayout, kept_bits, read_scene
from pddl_export.location_codec import FIELD_BITS, decode_location
from pddl_export.rules_io import PDDL_DIR
from pddl_export.symbolic import bits_from_codes
from symlearn.outputs import file_output, folder_output
from symlearn.problems.paths import check_safe_name, path_under
from symlearn.provenance import versions

LIFTED_FILE = "lifted.json"
LIFTED_DIR = "lifted"
DOMAIN_FILE = "domain.pddl"  # in LIFTED_DIR, and in each problem folder (write_problem_folder)
COST_FORM_DIR = "costs"  # a problem folder's all-outcomes cost form (write_problem_folder)
LIFTED_MAGIC = (b'{\n  "kind": "symlearn-lifted-rules"',)  # how a lifted.json the export wrote begins
DOMAIN_MAGIC = (b"; A lifted domain",)  # and its domain.pddl


SOURCES = ("observed", "network")


@dataclass(frozen=True)
class LiftedConfig:
    """How the lifted rules are distilled."""

    # whose next codes a move's outcome is: what the robot observed next ("observed"), or m(z)'s likeliest answer
    # ("network"). The kept learned bits of a moved object follow where it lands, which a lifted rule sees only
    # through its release location; rules of the observed outcomes are the more accurate on the held-out
    # splits (docs/DOMAIN.md), and m(z)'s answers still give each rule its share and alternatives
    source: str = "observed"
    # a move structure becomes a rule once it was seen this often: each rule's release grounds once per cube and
    # location, so this sets Fast Downward's translator time; 20 was chosen on a fresh 1-5-object data set
    # (experiments/heldout_accuracy.py on data/k15h) as the setting furthest above m(z)'s accuracy between 50 and 20,
    # and passes m(z) on a second one read once (docs/DOMAIN.md, "The rules against m(z) on 12,000 fresh steps")
    min_count: int = 20
    # a move that carries riders needs only this many: riders are 1.5% of objects, and without these rules the
    # domain could not state what Table I is about (a stick carries what stands on it); each is a stick schema of
    # its own, and those seen 3-5 times cost the translator more than they predict (6, chosen with min_count)
    rider_min_count: int = 6
    # a far-row stick's move names its two locations and grounds to a few actions: it needs only this many
    pair_min_count: int = 6
    # a structure of pool_classes rarer than min_count takes the majority of its pool (lifted_rules: the class,
    # place and what it lands on) once the pool has this many moves; 0 (the "fast" preset): no pooling. Each pooled
    # structure grounds once per cube and release location (a near-row stick's: per stick and pair of locations),
    # and the schemas' layer parameters weigh on Fast Downward's translator: the "accurate" preset
    # (LIFTED_PRESETS) pools cubes only, at about 2x Fast Downward's time
    pool_min_count: int = 0
    pool_classes: tuple = POOLED_CLASSES
    # a structure joins its pool once seen this often: each is a static fact of every problem and, per cube and
    # location, a ground action for the translator (5 keeps all of the validation splits' gain at 66 facts)
    pool_structure_min: int = POOL_STRUCTURE_MIN
    # a pick at a far-row stick's end (pddl_export.end_moves) names its three locations, as a far-row stick's move
    # names two: a class of them needs this many moves to become a rule; 0 (the "fast" preset): no end rules
    end_min_count: int = 0
    # and applies to the cases (the stick's level, the tops it leaves and finds) seen this often: each is a
    # static fact of every problem and one ground action per stick
    end_case_min: int = 2
    min_gain: float = MIN_GAIN  # a refinement must explain this share of a node's moves more (distil_lifted)
    min_info: float = 0.25  # a learned bit with this much mutual information (bits) with the location tracks it

    def __post_init__(self) -> None:
        for name in ("min_count", "rider_min_count", "pair_min_count", "pool_structure_min", "end_case_min"):
            v = getattr(self, name)
            if not (isinstance(v, int) and not isinstance(v, bool) and v >= 1):
                raise ValueError(f"{name}={v!r} must be a positive integer")
        if not (isinstance(self.pool_classes, (tuple, list)) and set(self.pool_classes) <= set(POOLED_CLASSES)):
            raise ValueError(f"pool_classes={self.pool_classes!r} must name some of {', '.join(POOLED_CLASSES)}")
        object.__setattr__(self, "pool_classes", tuple(self.pool_classes))
        for name in ("pool_min_count", "end_min_count"):
            v = getattr(self, name)
            if not (isinstance(v, int) and not isinstance(v, bool) and v >= 0):
                raise ValueError(f"{name}={v!r} must be a non-negative integer (0: none)")
        if self.source not in SOURCES:
            raise ValueError(f"source={self.source!r} must be one of {', '.join(SOURCES)}")
        if not 0 <= self.min_gain < 1:
            raise ValueError(f"min_gain={self.min_gain!r} must lie in [0, 1)")
        if not 0 < self.min_info <= 3:
            raise ValueError(f"min_info={self.min_info!r} must lie in (0, 3]")


# Named settings of `export-pddl` (--preset). "fast", the default and the shipped domain: the rules of structures
# seen min_count times, no pools and no end rules, which Fast Downward translates fastest. "accurate": rules of
# structures seen 30 times (rider moves 3), far-row pairs seen 10 times, the cube structures seen 12 times pooled,
# and picks at a far-row stick's end, chosen as the cheapest setting whose rules beat m(z) by at least 0.025 on
# the 1-5-object validation split (experiments/preset_sweep.py on problems/dev, against the earlier default of min count
# 50); it predicts what the robot saw next more often still, and Fast Downward takes about twice as long
# (docs/DOMAIN.md, "Two presets")
# "small": "fast" for a data set of a few thousand samples (the demo pipeline's), where a structure is seen a
# few times at most: it becomes a rule from 3 moves. This table is the one place the presets are defined
# (`export-pddl --preset` and the pipeline's presets name them).
LIFTED_PRESETS = {"fast": LiftedConfig(),
                  "accurate": LiftedConfig(min_count=30, rider_min_count=3, pair_min_count=10,
                                           pool_min_count=POOL_MIN_COUNT, pool_classes=("cube",),
                                           pool_structure_min=12, end_min_count=6),
                  "small": LiftedConfig(min_count=3)}


@dataclass(frozen=True)
class Split:
    """One split's codes as m(z) reads them, with actions and the recorded object types."""

    before: np.ndarray  # (N, K) int64, -1 padding
    after: np.ndarray
    action: np.ndarray  # (N,)
    mask: np.ndarray  # (N, K) bool
    stick: np.ndarray  # (N, K) bool: the recorded type (to name what a learned code is)


def split_codes(reader, data_dir: Path, split: str) -> Split:
    """One split of a data set (train, val, test) in the run's codes (reader: planning_models)."""
    from symlearn.data.dataset import load_split
    from symlearn.symbolic.symbols import encode_codes

    data = load_split(data_dir, split)
    mask = data.mask
    return Split(encode_codes(reader, data.pre_depth, data.pre_origin, mask),
                 encode_codes(reader, data.post_depth, data.post_origin, mask),
                 data.action.astype(np.int64), mask, data.obj_type == 1)


def network_steps(transition, codes: np.ndarray, actions: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """m(z)'s likeliest next codes for every row of (N, K) codes with -1 padding (rows grouped by object count)."""
    out = np.full(codes.shape, -1, np.int64)
    counts = mask.sum(1)
    for k in np.unique(counts):
        rows = np.flatnonzero(counts == k)
        if k == 0:
            continue
        out[rows, :k] = transition(codes[rows, :k].astype(np.int64), actions[rows].astype(np.int64))
    return out


def _fields(rules: LiftedRules, pieces) -> list[tuple]:
    return [(p.kind, p.loc, p.place, p.level) for p in pieces]


def case_of(pieces, action: int, fired: bool) -> str:
    """What the rules make of a step, given whether a rule fired on it (LiftedRules.step_pieces): "rule", "no
    rule" (a move whose structure has none: rarer than min_count), or why no lifted rule describes it
    (lifted_rules.participants: "same location", "nothing to pick", "a stick's end", ...)."""
    move = participants(read_scene(pieces), *divmod(int(action), 6))
    if fired:
        return "rule" if not isinstance(move, str) else f"{move}: an end rule"
    return move if isinstance(move, str) else "no rule"


@dataclass(frozen=True)
class StepCheck:
    """One step of a split, compared on what the domain states: the rules' next scene, m(z)'s and the observed."""

    objects: int
    case: str  # case_of: what the rules make of the step
    rules_right: bool  # the rules' next scene is the observed one
    net_right: bool  # m(z)'s likeliest next scene is the observed one
    agree: bool  # the rules' next scene is m(z)'s
    fired: bool  # a rule (or end rule) fired


def step_checks(rules: LiftedRules, split: Split, net_next: np.ndarray) -> Iterator[StepCheck]:
    """Each step of a split as the rules, m(z) (net_next: network_steps) and the world saw it, in order."""
    for n in range(len(split.action)):
        k = int(split.mask[n].sum())
        before = rules.pieces(split.before[n, :k].tolist())
        after, rule = rules.step_pieces(before, int(split.action[n]))
        mine = _fields(rules, after)
        net = _fields(rules, rules.pieces(net_next[n, :k].tolist()))
        seen = _fields(rules, rules.pieces(split.after[n, :k].tolist()))
        yield StepCheck(k, case_of(before, int(split.action[n]), rule is not None), mine == seen, net == seen,
                        mine == net, rule is not None)


def check_lifted(rules: LiftedRules, split: Split, net_next: np.ndarray) -> dict:
    """Whole-scene agreement on a split, by object count: the rules against m(z), each against the observation;
    where the two disagree, which one the world sides with; and the same by case (case_of), so the report says
    where the rules lose to m(z)."""
    tally: dict = {}
    for c in step_checks(rules, split, net_next):
        for group in ("all", "1-3" if c.objects <= 3 else "4-5"):
            g = tally.setdefault(group, {})
            for t in (g.setdefault("", Counter()), g.setdefault(c.case, Counter())):
                t["cases"] += 1
                t["rules_vs_net"] += c.agree
                t["rules_vs_observed"] += c.rules_right
                t["net_vs_observed"] += c.net_right
                t["rule_fired"] += c.fired
                if not c.agree:
                    t["disagree"] += 1
                    t["world_sides_with_rules"] += c.rules_right
                    t["world_sides_with_net"] += c.net_right

    def summary(t: Counter) -> dict:
        return {"cases": t["cases"], "fidelity_to_net": round(t["rules_vs_net"] / t["cases"], 4),
                "accuracy_rules": round(t["rules_vs_observed"] / t["cases"], 4),
                "accuracy_net": round(t["net_vs_observed"] / t["cases"], 4),
                "rule_fired": round(t["rule_fired"] / t["cases"], 4), "disagree": t["disagree"],
                "world_sides_with_rules": t["world_sides_with_rules"],
                "world_sides_with_net": t["world_sides_with_net"]}
    by_size = lambda g: sorted(((c, t) for c, t in g.items() if c), key=lambda x: -x[1]["cases"])  # noqa: E731
    return {group: {**summary(g[""]), "by_case": {c: summary(t) for c, t in by_size(g)}} for group, g in tally.items()}


@dataclass(frozen=True)
class TrainingMoves:
    """What the training splits of a run's data sets show, read once: the code layout, the type reader, every
    move with its outcome (LiftedConfig.source), m(z)'s answers on the same moves, the picks at a stick's end, and
    why the other steps are no move. distil_rules makes rules of it under any LiftedConfig of the same source and
    min_info (experiments/preset_sweep.py compares settings on one reading)."""

    layout: CodeLayout
    stick_of: object
    train: tuple  # Split per data set
    moves: tuple
    answers: tuple  # m(z)'s outcome of each move ("observed" source; else empty)
    ends: tuple
    why: Counter
    source: str
    min_info: float


def training_moves(reader, transition, sets: Sequence[Path], cfg: LiftedConfig) -> TrainingMoves:
    """The moves of the training splits of sets, in the run's codes (reader, transition: planning_models)."""
    train = [split_codes(reader, d, "train") for d in sets]
    code_bits = reader.bits - FIELD_BITS
    objects = np.concatenate([s.before[s.mask] for s in train])
    learned_codes, (locations, _, _) = decode_location(objects)
    learned = bits_from_codes(learned_codes, code_bits)
    layout = CodeLayout(code_bits, kept_bits(learned, locations, cfg.min_info))
    width = max(s.mask.shape[1] for s in train)
    stick_of = stick_reader(np.concatenate([_pad(s.before, width) for s in train]),
                            np.concatenate([_pad(s.mask, width) for s in train]),
                            np.concatenate([_pad(s.stick, width) for s in train]), layout)
    probe = LiftedRules(layout, stick_of)
    moves, answers, why, ends = [], [], Counter(), []
    for s in train:
        net = network_steps(transition, s.before, s.action, s.mask)
        m, w = observed_moves(probe, s.before, s.after if cfg.source == "observed" else net, s.action, s.mask)
        ends += observed_end_moves(probe, s.before, s.after if cfg.source == "observed" else net, s.action, s.mask)
        moves += m
        why.update(w)
        if cfg.source == "observed":
            answers += observed_moves(probe, s.before, net, s.action, s.mask)[0]
    return TrainingMoves(layout, stick_of, tuple(train), tuple(moves), tuple(answers), tuple(ends), why,
                         cfg.source, cfg.min_info)


def distil_rules(seen: TrainingMoves, cfg: LiftedConfig, model_hash: str) -> LiftedRules:
    """The lifted rules (with their end rules) of the moves seen, under cfg's counts and pooling."""
    if (cfg.source, cfg.min_info) != (seen.source, seen.min_info):
        raise ValueError(f"moves read with source={seen.source!r}, min_info={seen.min_info} cannot be distilled "
                         f"under source={cfg.source!r}, min_info={cfg.min_info}")
    rules = distil_lifted(seen.layout, seen.stick_of, list(seen.moves), cfg.min_count, model_hash,
                          rider_min_count=min(cfg.rider_min_count, cfg.min_count),
                          pair_min_count=cfg.pair_min_count, min_gain=cfg.min_gain,
                          pool_min_count=cfg.pool_min_count or None, pool_structure_min=cfg.pool_structure_min,
                          pool_classes=cfg.pool_classes)
    if seen.answers:  # each rule's share and alternatives are m(z)'s answers on the moves it covers
        rules = with_network_answers(rules, list(seen.answers))
    found = distil_end_rules(list(seen.ends), cfg.end_min_count, cfg.end_case_min) if cfg.end_min_count else ()
    return dataclasses.replace(rules, end_rules=found, stats={**rules.stats, "end_moves": len(seen.ends)})


def export_lifted(run_dir: Path, data_dir: Path, extra_data: tuple[Path, ...] = (), cfg: LiftedConfig = LiftedConfig(),
                  out_dir: Path | None = None) -> dict:
    """Distil, write and check the lifted domain of a run; returns its report (also in lifted.json)."""
    from symlearn.data.dataset import data_fingerprint, data_records, distinct_extra_data
    from symlearn.symbolic.learned_transition import planning_models
    from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE

    run_dir = Path(run_dir)
    out = Path(out_dir) if out_dir else run_dir / PDDL_DIR
    domain_path, lifted_path = lifted_outputs(out, "--out" if out_dir else "--run")  # before minutes of work
    reader, transition = planning_models(run_dir)
    if reader.location_bits != FIELD_BITS:
        raise ValueError(f"{run_dir / TRANSITION_FILE}: a lifted domain needs m(z) on {FIELD_BITS} location bits "
                         f"(train-transition --preset recommended, or [transition] location_bits = {FIELD_BITS} "
                         f"in its --config); this one has {reader.location_bits}")
    model_hash = sha256_file(run_dir / TRANSITION_FILE)[:16]
    extra_data = distinct_extra_data(data_dir, extra_data)
    t0 = time.perf_counter()
    sets = [Path(d) for d in (data_dir, *extra_data)]
    seen = training_moves(reader, transition, sets, cfg)
    rules = distil_rules(seen, cfg, model_hash)
    layout, stick_of, train, why = seen.layout, seen.stick_of, seen.train, seen.why
    probe = LiftedRules(layout, stick_of)
    width = max(s.mask.shape[1] for s in train)
    t_distil = time.perf_counter() - t0
    checks = {}
    for d in sets:
        test = split_codes(reader, d, "test")
        checks[str(d)] = check_lifted(rules, test, network_steps(transition, test.before, test.action, test.mask))
    domain = domain_pddl(rules)
    report = {"run": str(run_dir), "model_hash": model_hash, "config": asdict(cfg), "data": str(data_dir),
              "data_fingerprint": data_fingerprint(data_dir), "extra_data": data_records(extra_data),
              "kept_bits": list(layout.kept), "position_bits": [b for b in range(layout.code_bits) if b not in layout.kept],
              "moves_not_described": dict(why), "checks_test_split": checks, "domain_bytes": len(domain.encode()),
              "n_schemas": len(schemas(rules)), "seconds": round(time.perf_counter() - t0, 1),
              "distil_seconds": round(t_distil, 1), "versions": versions()}
    codebook = build_codebook(probe, np.concatenate([_pad(s.before, width) for s in train]
                                                    + [_pad(s.after, width) for s in train]),
                              np.concatenate([_pad(s.mask, width) for s in train] * 2))
    rules = LiftedRules(layout, stick_of, rules.rules, model_hash,
                        {**rules.stats, **report, "end_rules": len(rules.end_rules)}, codebook, rules.end_rules)
    atomic_write_files({domain_path: domain, lifted_path: json_text(rules.to_json())})  # replaced as one unit
    return rules.stats


def lifted_outputs(pddl_dir: Path, flag: str = "--out") -> tuple[Path, Path]:
    """The files export_lifted replaces together, PDDL_DIR/lifted/domain.pddl and PDDL_DIR/lifted.json, checked
    before any work (symlearn.outputs): the folders no files, the files absent or what the export itself wrote
    there (never a user's file of that name); ValueError in one line naming `flag` and the path."""
    pddl_dir = folder_output(Path(pddl_dir), flag)
    folder_output(pddl_dir / LIFTED_DIR, flag)
    return (file_output(pddl_dir / LIFTED_DIR / DOMAIN_FILE, flag, kind="a lifted domain", magic=DOMAIN_MAGIC),
            file_output(pddl_dir / LIFTED_FILE, flag, kind="a lifted-rules JSON", magic=LIFTED_MAGIC))


def check_problem_folder(folder: Path, flag: str) -> Path:
    """A folder write_problem_folder may replace whole: absent, or one holding only what it writes (.pddl and .json
    files, costs/); refused in one line naming `flag` otherwise (a file, a link, a folder of other files), before
    any work. Returns the folder."""
    folder = folder_output(Path(folder), flag)
    if folder.is_symlink():
        raise ValueError(f"{flag}: {folder} is a symbolic link; refusing to replace it")
    if folder.is_dir() and any(p.suffix not in (".pddl", ".json") and p.name != COST_FORM_DIR
                               for p in folder.iterdir()):
        raise ValueError(f"{flag}: {folder} holds files other than a problem folder's; give another folder")
    return folder


def problem_folder(pddl_dir: Path, problems_dir: Path) -> Path:
    """Where export-pddl writes a problem set's standalone folder: PDDL_DIR/lifted/NAME, NAME the name of the set's
    folder itself (its resolved path: `--problems ..` names the folder it is), a safe name (symlearn.problems.paths)
    other than the domain's file; checked as check_problem_folder does."""
    flag = f"--problems {problems_dir}"
    name = check_safe_name(Path(problems_dir).resolve().name, flag)
    if name == DOMAIN_FILE:
        raise ValueError(f"{flag}: a problem folder cannot be named {DOMAIN_FILE}, the lifted domain's file")
    return check_problem_folder(path_under(Path(pddl_dir) / LIFTED_DIR, name), flag)


def export_paths(run_dir: Path, out_dir: Path | None, problem_sets: Sequence[Path] = ()) -> dict[Path, Path]:
    """Every path a lifted `export-pddl` writes, checked before any work (the distillation takes minutes): its
    --out (default RUN/pddl), the domain and lifted.json there (lifted_outputs) and one folder per problem set
    (problem_folder); two sets whose folders share a name are refused, naming both. Returns each set's folder."""
    pddl_dir = Path(out_dir) if out_dir else Path(run_dir) / PDDL_DIR
    lifted_outputs(pddl_dir, "--out" if out_dir else "--run")
    folders: dict[Path, Path] = {}
    for d in map(Path, problem_sets):
        folder = problem_folder(pddl_dir, d)
        other = next((o for o, f in folders.items() if f == folder), None)
        if other is not None:
            raise ValueError(f"--problems {other} and {d} would both be written to {folder}; give sets whose "
                             f"folders have different names")
        folders[d] = folder
    return folders


def _pad(a: np.ndarray, k: int) -> np.ndarray:
    """Object slots padded to k (with -1 for codes, False for masks and types)."""
    fill = -1 if a.dtype.kind in "iu" else False
    return np.pad(a, ((0, 0), (0, k - a.shape[1])), constant_values=fill)


MAX_DATA_OBJECTS = 5  # the most objects a scene of the data sets had: problems beyond it are zero-shot


def write_problem_folder(run_dir: Path, problems_dir: Path, out_dir: Path | None = None,
                         pddl_dir: Path | None = None, rules: LiftedRules | None = None) -> dict:
    """A standalone benchmark folder of a problem set: the lifted domain.pddl and one pNN.pddl per problem, and
    the same in the domain's all-outcomes cost form under costs/ (COST_FORM_DIR: `:action-costs`, for a cost-aware
    search such as A* with LM-cut).

    Each problem's start and goal are the run's codes of its scenes (rendered in the simulator), as the
    planners see them; index.json maps pNN to the source problem, its object count and shortest plan length
    where the problem file records it. Loading the folder needs no torch, no pybullet: only a PDDL planner. The
    rules are read from pddl_dir (default RUN/pddl: export-pddl's --out) unless given, and the folder goes beside
    them (problem_folder). The folder is written whole (a temp folder renamed into place: an earlier one is replaced
    with no stale file left), and only where check_problem_folder allows it, which is checked first.
    Returns the index; problems with more objects than the data ever showed are listed under `zero_shot`.
    """
    from pddl_export.lifted_rules_io import load_lifted
    from pddl_export.lifted_domain import static_facts
    from pddl_export.lifted_moves import moves
    from pddl_export.lifted_problem import problem_pddl
    from symlearn.problems.problem import load_problems
    from symlearn.symbolic.scenes import scene_codes, symbolic_goal
    from symlearn.sim.simulator import TabletopSimulator
    from symlearn.symbolic.learned_transition import planning_models

    run_dir, problems_dir = Path(run_dir), Path(problems_dir)
    pddl_dir = Path(pddl_dir) if pddl_dir else run_dir / PDDL_DIR  # where export_lifted wrote (its out_dir)
    out = check_problem_folder(Path(out_dir), "out_dir") if out_dir else problem_folder(pddl_dir, problems_dir)
    rules = rules if rules is not None else load_lifted(pddl_dir / LIFTED_FILE)
    problems = load_problems(problems_dir)  # refuses a missing or empty folder before any work
    reader, _ = planning_models(run_dir)
    index = {"domain": "domain.pddl", "cost_form": f"{COST_FORM_DIR}/domain.pddl", "model_hash": rules.model_hash,
             "source": str(problems_dir), "problems": {}, "zero_shot": []}
    texts = {}
    statics = {costs: static_facts(moves(rules, costs)) for costs in (False, True)}  # once, not per problem
    sim = TabletopSimulator()
    try:
        for n, (path, problem) in enumerate(problems):
            name = f"p{n + 1:02d}"
            goal = symbolic_goal(sim, reader, problem)
            start = [int(c) for c in scene_codes(sim, reader, problem.initial)]
            texts[name] = problem_pddl(rules, start, goal, name, statics=statics[False])
            texts[f"{COST_FORM_DIR}/{name}"] = problem_pddl(rules, start, goal, name, costs=True, statics=statics[True])
            index["problems"][name] = {"file": path.name, "objects": problem.k,
                                       "optimal_length": getattr(problem, "optimal_length", None)}
            if problem.k > MAX_DATA_OBJECTS:
                index["zero_shot"].append(name)
    finally:
        sim.close()
    files = {DOMAIN_FILE: domain_pddl(rules), f"{COST_FORM_DIR}/{DOMAIN_FILE}": domain_pddl(rules, costs=True)}
    files.update({f"{name}.pddl": text for name, text in texts.items()})
    atomic_write_folder(out, {**files, "index.json": json_text(index)})
    return index
