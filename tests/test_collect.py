import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from symlearn.sim.collect import CollectConfig, CollectError, collect, collect_shard, shard_name
from symlearn.data.dataset import ARRAY_NAMES, DataError, load_manifest, load_split, summarize
from symlearn.data.model_input import model_inputs
from symlearn.sim.exploration import ExplorationConfig
from symlearn.world import N_LOCATIONS

CFG = CollectConfig(n=24, seed=3, shard_size=2)


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    out = tmp_path_factory.mktemp("data") / "tiny"
    collect(out, CFG, workers=1, show_progress=False)
    return out


def test_manifest_and_splits(tiny):
    m = load_manifest(tiny)
    assert m["complete"] and m["n_shards"] == 12
    assert m["counts"] == {"train": 20, "val": 2, "test": 2}
    assert m["settings"]["seed"] == 3 and "pybullet" in m["versions"]
    train = load_split(tiny, "train")
    assert len(train) == 20 and train.pre_depth.shape == (20, 3, 64, 64)
    assert train.pre_depth.dtype == np.float16 and train.effect.shape == (20, 3, 3)
    assert set(np.unique(train.action)) <= set(range(36))
    # padding rows are empty; real rows have types and (mostly) visible crops
    assert np.all(train.obj_type[~train.mask] == -1) and np.all(train.effect[~train.mask] == 0)
    assert np.all(train.obj_type[train.mask] >= 0)
    # each step's post-state is the next step's pre-state within an episode
    same_ep = (train.episode[1:] == train.episode[:-1]) & (train.step[1:] == train.step[:-1] + 1)
    assert same_ep.any()
    np.testing.assert_array_equal(train.post_depth[:-1][same_ep], train.pre_depth[1:][same_ep])
    np.testing.assert_allclose(train.effect[train.mask],
                               (train.post_pose[..., :3] - train.pre_pose[..., :3])[train.mask], atol=1e-6)


def test_model_inputs_shapes(tiny):
    d = load_split(tiny, "val")
    x = model_inputs(d.pre_depth, d.pre_origin)
    assert x.shape == (2, 3, 3, 64, 64) and x.dtype == np.float32
    assert 0 <= x[:, :, 1:].min() and x[:, :, 1:].max() <= 1.3  # windows may reach past the border
    with pytest.raises(DataError, match="shape"):
        model_inputs(d.pre_depth[:, :, 0], d.pre_origin)


def test_same_seed_same_arrays_with_two_workers(tiny, tmp_path):
    out = tmp_path / "again"
    collect(out, CFG, workers=2, show_progress=False)
    for split in ("train", "val", "test"):
        a, b = load_split(tiny, split), load_split(out, split)
        for name in ARRAY_NAMES:
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_resume_redoes_only_missing_shards(tmp_path):
    out = tmp_path / "resume"
    cfg = CollectConfig(n=12, seed=1, shard_size=1)
    collect(out, cfg, show_progress=False)
    before = {p.name: p.stat().st_mtime_ns for p in out.glob("shard_*.npz")}
    (out / shard_name(5)).unlink()
    m = collect(out, cfg, show_progress=False)
    after = {p.name: p.stat().st_mtime_ns for p in out.glob("shard_*.npz")}
    assert m["complete"] and set(after) == set(before)
    changed = [n for n in after if after[n] != before.get(n)]
    assert changed == [shard_name(5)]


def test_a_data_set_collected_before_the_scene_draw_keys_resumes(tmp_path):
    # manifests written before scene_draw and far_prob existed lack them; they had the near-row draw, so the same
    # arguments resume them, and a far-stick request is still refused
    out = tmp_path / "old"
    cfg = CollectConfig(n=12, seed=1, shard_size=1)
    collect(out, cfg, show_progress=False)
    m = json.loads((out / "manifest.json").read_text())
    for key in ("scene_draw", "far_prob"):
        del m["settings"]["exploration"][key]
    (out / "manifest.json").write_text(json.dumps(m))
    (out / shard_name(3)).unlink()
    assert collect(out, cfg, show_progress=False)["complete"]
    far = dataclasses.replace(cfg, exploration=dataclasses.replace(cfg.exploration, scene_draw="far-stick"))
    with pytest.raises(CollectError, match="different settings.*scene_draw"):
        collect(out, far, show_progress=False)


def test_different_settings_refused(tiny):
    with pytest.raises(CollectError, match="different settings.*seed"):
        collect(tiny, CollectConfig(n=24, seed=4, shard_size=2), show_progress=False)


def test_foreign_directory_refused(tmp_path):
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(CollectError, match="not a symlearn data set"):
        collect(tmp_path, CFG, show_progress=False)


def test_corrupted_and_truncated_shards_detected(tiny, tmp_path):
    import shutil

    copy = tmp_path / "copy"
    shutil.copytree(tiny, copy)
    shard = copy / shard_name(0)
    data = bytearray(shard.read_bytes())
    data[len(data) // 2] ^= 0xFF
    shard.write_bytes(bytes(data))
    with pytest.raises(DataError, match="shard_00000.npz is corrupted"):
        load_split(copy, "train")
    shard.write_bytes(bytes(data[: len(data) // 3]))
    with pytest.raises(DataError, match="corrupted or truncated"):
        load_split(copy, "train")
    (copy / shard_name(11)).unlink()
    with pytest.raises(DataError, match="missing"):
        load_split(copy, "test")


def test_missing_foreign_and_old_format_refused(tmp_path):
    with pytest.raises(DataError, match="manifest.json missing"):
        load_manifest(tmp_path)
    (tmp_path / "manifest.json").write_text(json.dumps({"kind": "other"}))
    with pytest.raises(DataError, match="not a symlearn"):
        load_manifest(tmp_path)
    (tmp_path / "manifest.json").write_text(json.dumps({"kind": "symlearn-interaction-data", "format_version": 99}))
    with pytest.raises(DataError, match="format version 99"):
        load_manifest(tmp_path)
    with pytest.raises(DataError, match="unknown split"):
        load_split(tmp_path, "dev")


@pytest.mark.parametrize("kw,msg", [({"k_values": (11,), "k_probs": (1.0,)}, "out of range"),
                                    ({"k_values": (0, 1), "k_probs": (0.5, 0.5)}, "out of range"),
                                    ({"k_probs": (0.5, 0.5, 0.5)}, "sum to 1")])
def test_bad_exploration_settings_refused(kw, msg):
    with pytest.raises(ValueError, match=msg):
        ExplorationConfig(**kw)


def test_cli_collect_and_refusals(tmp_path):
    out = tmp_path / "cli"
    (tmp_path / "shards.toml").write_text("[collect]\nshard_size = 1\n")
    run = [sys.executable, "-m", "symlearn.cli.main", "collect", "--out", str(out), "--n", "12",
           "--config", str(tmp_path / "shards.toml"), "--objects", "4-5", "--quiet"]
    r = subprocess.run(run, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    summary = json.loads(r.stdout)
    assert summary["samples"] == 12 and summary["objects_per_sample"] >= 4
    assert load_split(out, "all").pre_depth.shape[1] == 5  # padded to the largest scene
    bad = subprocess.run(run[:-2] + ["0-6", "--quiet"], capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "out of range" in bad.stderr and len(bad.stderr.strip().splitlines()) == 1
    assert summarize(out)["shards"] == 12
    far = tmp_path / "far"  # the shipped recipe of data/carry: --objects over the settings file's scene draw
    recipe = Path(__file__).resolve().parents[1] / "pretrained" / "relations_carry" / "collect_far_stick.toml"
    r = subprocess.run(run[:4] + ["--out", str(far), "--n", "12", "--objects", "2-4", "--config", str(recipe), "--quiet"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    exploration = load_manifest(far)["settings"]["exploration"]
    assert exploration == json.loads(json.dumps(dataclasses.asdict(ExplorationConfig.far_stick(2, 4))))
    types = load_split(far, "all").obj_type
    assert (types == 1).sum(1).tolist() == [1] * 12  # one stick a scene


class _DroppingSim:
    """A stand-in simulator whose every action drops an object off the table."""

    def __init__(self, cfg):
        self.steps = 0

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def build(self, spec):
        pass

    def observe(self):
        return None

    def occupied(self):
        return np.ones(N_LOCATIONS, bool)

    def step(self, action):
        self.steps += 1
        return type("Res", (), {"off_table": True})()


def test_collect_shard_gives_up_after_failed_episodes(monkeypatch):
    monkeypatch.setattr("symlearn.sim.collect.TabletopSimulator", _DroppingSim)
    with pytest.raises(CollectError, match="shard 0: 5 episodes in a row recorded no sample"):
        collect_shard(CFG, 0, 2, max_failed_episodes=5)


def test_authors_type_draw_matches_their_protocol():
    """First k of a shuffled (stick, cube, cube): every 3-object scene has one stick, a third of objects are sticks."""
    from symlearn.sim.exploration import sample_types
    from symlearn.world import ObjectType
    rng = np.random.default_rng(0)
    cfg = ExplorationConfig()
    assert cfg.type_draw == "authors"
    three = [sample_types(rng, cfg, 3) for _ in range(300)]
    assert all(t.count(ObjectType.STICK) == 1 for t in three)
    two = np.mean([sample_types(rng, cfg, 2).count(ObjectType.STICK) for _ in range(3000)])
    one = np.mean([sample_types(rng, cfg, 1)[0] == ObjectType.STICK for _ in range(3000)])
    assert abs(two - 2 / 3) < 0.03 and abs(one - 1 / 3) < 0.03
    five = [sample_types(rng, cfg, 5) for _ in range(100)]
    assert all(t.count(ObjectType.STICK) == 1 for t in five)


def test_independent_type_draw_allows_scenes_without_stick():
    from symlearn.sim.exploration import sample_types
    from symlearn.world import ObjectType
    rng = np.random.default_rng(0)
    cfg = ExplorationConfig(type_draw="independent")
    counts = [sample_types(rng, cfg, 3).count(ObjectType.STICK) for _ in range(2000)]
    assert max(counts) == 1 and 0.2 < np.mean(np.array(counts) == 0) < 0.35  # (1 - 0.35)^3 = 0.27
    with pytest.raises(ValueError, match="type_draw"):
        ExplorationConfig(type_draw="random")


def test_far_stick_scenes_put_the_stick_in_the_far_row_and_carry_riders():
    """far-stick scenes: the stick first and in the far row, cubes in the far row at about far_prob; collected in the
    simulator, picking the stick carries what rests on it in a good share of the actions (about 1 in 5; near-row
    scenes about 1 in 35)."""
    from symlearn.sim.exploration import sample_scene_spec
    from symlearn.world import FAR_ROW, ObjectType
    rng = np.random.default_rng(0)
    cfg = ExplorationConfig.far_stick(2, 4)
    specs = [sample_scene_spec(rng, cfg) for _ in range(500)]
    assert all(s[0][0] == ObjectType.STICK and s[0][1] in FAR_ROW for s in specs)
    assert all(t == ObjectType.CUBE for s in specs for t, _ in s[1:]) and {len(s) for s in specs} == {2, 3, 4}
    far = np.mean([loc in FAR_ROW for s in specs for _, loc in s[1:]])
    assert abs(far - cfg.far_prob) < 0.05
    with pytest.raises(ValueError, match="scene_draw"):
        ExplorationConfig(scene_draw="anywhere")
    with pytest.raises(ValueError, match="far_prob"):
        ExplorationConfig(far_prob=1.5)
    a = collect_shard(CollectConfig(n=40, seed=1, exploration=cfg), 0, 40)
    carried = 0
    for i in range(40):
        g, k = int(a["grasped"][i]), int(a["n_objects"][i])
        if g >= 0 and a["obj_type"][i, g] == int(ObjectType.STICK):
            moved = np.linalg.norm(a["effect"][i, :k, :2], axis=1) >= 0.1
            moved[g] = False
            carried += bool(moved.any())
    assert carried >= 3
