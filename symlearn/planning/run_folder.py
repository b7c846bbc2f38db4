"""A run folder as a read-only input of planning: its layout, and its models and rules loaded with the hash checks.

Training and export write a run (RUN/best.pt, transition.pt, pddl/...); planning only reads it. `plan` keeps
its planners' task files in a work folder removed afterwards, or beside its recording, and `benchmark` keeps
none (symlearn.planning.plan_one, symlearn.planning.benchmark), so a shipped run such as pretrained/recommended is
planned on as it is, read-only too. `Run` names every file planning reads; its models come through the one
guarded checkpoint loader (symlearn.learning.checkpoint.guarded_blob), and what is stale is refused in one line:
an m(z) trained on another best.pt (LearnedTransition.from_run), rules or a lifted domain exported from another
transition.pt (Run.check_current).

    >>> run = Run(Path("pretrained/recommended"))                    # doctest: +SKIP
    >>> lifted = run.lifted()                                         # doctest: +SKIP
    >>> encoder, transition = run.planning_models()                  # doctest: +SKIP
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from pddl_export.files import sha256_file
from pddl_export.outcome_rules import OUTCOMES_FILE
from pddl_export.rules_io import PDDL_DIR, RULES_FILE
from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE

if TYPE_CHECKING:
    from pddl_export.lifted_rules import LiftedRules
    from pddl_export.outcome_rules import OutcomeRules
    from pddl_export.rules import RuleSet
    from symlearn.symbolic.learned_transition import LearnedTransition
    from symlearn.symbolic.transition_data import SymbolReader

EFFECT_MODEL_FILE = "best.pt"
MODEL_HASH_CHARS = 16  # the sha256 prefix export-pddl records as the rules' model_hash


@dataclass(frozen=True)
class Run:
    """One run folder, read only: where each file planning reads lies, and its loaders with their checks."""

    path: Path

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", Path(self.path))

    @property
    def effect_model_file(self) -> Path:
        """RUN/best.pt: the effect model, whose encoder reads crops into codes."""
        return self.path / EFFECT_MODEL_FILE

    @property
    def transition_file(self) -> Path:
        """RUN/transition.pt: m(z)."""
        return self.path / TRANSITION_FILE

    @property
    def rules_file(self) -> Path:
        """RUN/pddl/rules.json: the rules over whole codes (export-pddl --rules)."""
        return self.path / PDDL_DIR / RULES_FILE

    @property
    def outcomes_file(self) -> Path:
        """RUN/pddl/outcomes.json: each object's second likeliest outcome, distilled into rules."""
        return self.path / PDDL_DIR / OUTCOMES_FILE

    @property
    def lifted_file(self) -> Path:
        """RUN/pddl/lifted.json: the lifted rules the lifted domain is written from (export-pddl)."""
        from symlearn.export.lifted_export import LIFTED_FILE

        return self.path / PDDL_DIR / LIFTED_FILE

    def transition_hash(self) -> str:
        """The first 16 hex digits of transition.pt's sha256 (what exports record); refused if it is missing."""
        if not self.transition_file.is_file():
            raise ValueError(f"no transition model at {self.transition_file}; run 'symlearn train-transition' first")
        return sha256_file(self.transition_file)[:MODEL_HASH_CHARS]

    def check_current(self, model_hash: str, exported: Path | None = None) -> None:
        """Refuse an export (default rules.json) made from another transition.pt than the run's, by the hash it
        records: its plans would be another model's."""
        current = self.transition_hash()
        if not model_hash or model_hash != current:
            raise ValueError(f"{exported or self.rules_file} was exported from another transition.pt "
                             f"(model_hash {model_hash or 'missing'}, {TRANSITION_FILE} is {current}); "
                             f"re-run 'symlearn export-pddl --run {self.path} --rules'")

    def rules(self) -> tuple[RuleSet, str]:
        """RUN/pddl/rules.json and its model hash, refused if missing or stale."""
        from pddl_export.rules_io import load_rules

        rules, model_hash = load_rules(self.path)
        self.check_current(model_hash)
        return rules, model_hash

    def outcomes(self, model_hash: str) -> OutcomeRules:
        """RUN/pddl/outcomes.json, refused if it comes from another transition model than rules of model_hash."""
        from pddl_export.outcome_rules import load_outcomes

        outcomes, outcomes_hash = load_outcomes(self.path)
        if outcomes_hash != model_hash:
            raise ValueError(f"{self.path / PDDL_DIR} holds rules.json and outcomes.json of different "
                             f"transition models; re-run 'symlearn export-pddl --run {self.path} --rules'")
        return outcomes

    def lifted(self) -> LiftedRules:
        """RUN/pddl/lifted.json, refused if missing or exported from another transition.pt than the run's."""
        from pddl_export.lifted_rules_io import load_lifted

        path = self.lifted_file
        if not path.is_file():
            raise ValueError(f"no lifted domain at {path}; run 'symlearn export-pddl --run {self.path}' "
                             f"(it needs an m(z) on 9 location bits)")
        lifted = load_lifted(path)
        self.check_current(lifted.model_hash, path)
        return lifted

    def planning_models(self) -> tuple[SymbolReader, LearnedTransition]:
        """The run's m(z) and the reader of crops into its codes (best.pt checked first, then transition.pt and
        that it was trained on this best.pt)."""
        from symlearn.symbolic.learned_transition import planning_models

        return planning_models(self.path)

