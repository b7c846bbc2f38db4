"""Every analysis output records its config, seed, package versions and the hashes of what it read."""
from __future__ import annotations

import hashlib
import json

import pytest

from symlearn.learning.evaluation import evaluate
from symlearn.learning.table1 import CASES, table1
from symlearn.learning.training import TrainConfig, train
from symlearn.provenance import versions
from symlearn.sim.collect import CollectConfig, collect
from symlearn.symbolic.symbols import analyse_symbols
from symlearn.symbolic.transition_model import TransitionConfig
from symlearn.symbolic.transition_training import METRICS_FILE, train_transition

SEED = 3


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    root = tmp_path_factory.mktemp("provenance")
    collect(root / "data", CollectConfig(n=24, seed=4, shard_size=2), show_progress=False)
    train(root / "data", root / "run", TrainConfig.from_preset("quick", epochs=1, batch_size=8, bf16=False, seed=SEED),
          show_progress=False)
    return root


def _file_hash(path) -> str:
    """SHA-256 of a file, computed here without the toolkit's helper, first 16 hex digits."""
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16]


def _data_hash(data_dir) -> str:
    """The data fingerprint recomputed from the shard files themselves (not from the manifest)."""
    shards = sorted(data_dir.glob("shard_*.npz"))
    assert shards
    digests = sorted(hashlib.sha256(p.read_bytes()).hexdigest() for p in shards)
    return hashlib.sha256("".join(digests).encode()).hexdigest()[:16]


def _check_record(saved: dict, run_dir) -> None:
    assert saved["seed"] == SEED  # the effect model's training seed
    assert saved["versions"] == json.loads(json.dumps(versions())) and "torch" in saved["versions"]
    assert saved["effect_model_sha256"] == _file_hash(run_dir / "best.pt")


def test_eval_json_records_config_seed_versions_and_hashes(run):
    evaluate(run / "run", run / "data", baseline_run=run / "run")
    saved = json.loads((run / "run" / "eval.json").read_text())
    _check_record(saved, run / "run")
    assert saved["config"] == {"run": str(run / "run"), "data": str(run / "data"), "baseline_run": str(run / "run")}
    assert saved["data_fingerprint"] == _data_hash(run / "data") == saved["trained_on"]
    assert saved["ablations"]["no_attention"]["effect_model_sha256"] == _file_hash(run / "run" / "best.pt")


def test_symbols_json_records_config_seed_versions_and_hashes(run):
    analyse_symbols(run / "run", run / "data", min_count=1)
    saved = json.loads((run / "run" / "symbols.json").read_text())
    _check_record(saved, run / "run")
    assert saved["config"] == {"run": str(run / "run"), "data": str(run / "data"), "symbol": None, "min_count": 1}
    assert saved["data_fingerprint"] == _data_hash(run / "data")


def test_table1_json_records_config_seed_versions_and_hashes(run):
    table1(run / "run")
    saved = json.loads((run / "run" / "table1.json").read_text())
    _check_record(saved, run / "run")
    assert saved["config"] == {"run": str(run / "run"), "cases": list(CASES)}


def test_transition_metrics_record_config_seed_versions_and_hashes(run):
    cfg = TransitionConfig.from_preset("quick", epochs=1)
    train_transition(run / "run", run / "data", cfg, seed=11)
    saved = json.loads((run / "run" / METRICS_FILE).read_text())
    assert saved["seed"] == 11
    assert TransitionConfig.from_json(saved["transition_config"]) == TransitionConfig.from_preset("quick", epochs=1, code_bits=8)
    assert saved["versions"] == json.loads(json.dumps(versions()))
    assert saved["effect_model_sha256"] == _file_hash(run / "run" / "best.pt")
    assert saved["data_fingerprint"] == _data_hash(run / "data")


def test_bench_context_names_the_machine_the_date_and_the_versions():
    import platform
    import re

    from symlearn.provenance import bench_context

    ctx = bench_context()
    assert list(ctx) == ["machine", "cpus", "date", "versions"] and ctx["cpus"] >= 1
    assert ctx["machine"].startswith(platform.machine() + ", ") and re.fullmatch(r"\d{4}-\d\d-\d\d", ctx["date"])
    assert ctx["versions"] == versions()
