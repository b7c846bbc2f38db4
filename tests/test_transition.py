"""The symbolic transition model m(z): architecture, masked loss, training files, checkpoint, protocol."""
from __future__ import annotations

import json

import numpy as np
import pytest
import torch

from conftest import TINY_TRANSITION_ARGS, cli, cli_json, recomputed_transition_accuracy, write_config
from search.learned_astar import plan_symbolic
from pddl_export.symbolic import SymbolicGoal
from symlearn.learning.checkpoint import load_effect_model
from symlearn.data.dataset import data_fingerprint, load_split
from symlearn.learning.training import TrainConfig
from symlearn.symbolic.learned_transition import LearnedTransition
from symlearn.symbolic.transition_checkpoint import TRANSITION_FILE, TransitionError, load_transition, save_transition
from symlearn.symbolic.transition_data import (TransitionData, build_transition_data, concat_transition_data,
                                               encode_observation)
from symlearn.symbolic.transition_metrics import ROLLOUT_STEPS, rollout_chains
from symlearn.symbolic.transition_model import TransitionConfig, TransitionNet, masked_bce
from symlearn.symbolic.transition_training import METRICS_FILE
from symlearn.world import N_ACTIONS, ObjectType

BITS = 8


def _net(seed: int = 0, **over) -> TransitionNet:
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(seed)
        return TransitionNet(TransitionConfig.from_preset("quick", code_bits=BITS, **over)).eval()


@pytest.fixture(scope="module")
def run(tiny_run):
    """The session's tiny run (a one-epoch effect model, a 3-epoch transition model), its data and metrics."""
    return tiny_run.path, tiny_run.data, json.loads((tiny_run.path / METRICS_FILE).read_text())


# ------------------------------------------------------------------------------- architecture


def test_forward_shapes_and_padding_is_ignored():
    net = _net()
    g = torch.Generator().manual_seed(0)
    codes = torch.randint(0, 2, (4, 3, BITS), generator=g).float()
    mask = torch.tensor([[1, 1, 1], [1, 1, 0], [1, 0, 0], [0, 0, 0]]).bool()
    act = torch.tensor([0, 7, 21, 35])
    with torch.no_grad():
        out = net(codes, mask, act)
        noisy = codes.clone()
        noisy[~mask] = 1.0 - noisy[~mask]  # padded slots hold garbage
        out2 = net(noisy, mask, act)
    assert out.logits.shape == (4, 3, BITS) and out.codes.shape == (4, 3, BITS)
    assert torch.isfinite(out.logits).all()  # even the scene without real objects
    assert (out.logits[~mask] == 0).all() and (out.codes[~mask] == 0).all()
    torch.testing.assert_close(out.logits[mask], out2.logits[mask])
    assert set(out.codes.unique().tolist()) <= {0.0, 1.0}


def test_forward_refuses_bad_shapes():
    net = _net()
    with pytest.raises(ValueError, match="codes must be"):
        net(torch.zeros(2, 3, BITS + 1), torch.ones(2, 3, dtype=torch.bool), torch.zeros(2, dtype=torch.long))
    with pytest.raises(ValueError, match="actions must be"):
        net(torch.zeros(2, 3, BITS), torch.ones(2, 3, dtype=torch.bool), torch.zeros(3, dtype=torch.long))


def test_bce_counts_real_objects_only():
    g = torch.Generator().manual_seed(1)
    logits = torch.randn(3, 4, BITS, generator=g)
    target = torch.randint(0, 2, (3, 4, BITS), generator=g).float()
    mask = torch.tensor([[1, 1, 0, 0], [1, 0, 0, 0], [1, 1, 1, 1]]).bool()
    want = torch.nn.functional.binary_cross_entropy_with_logits(logits[mask], target[mask])
    torch.testing.assert_close(masked_bce(logits, target, mask), want)
    logits2 = logits.clone()
    logits2[~mask] = 100.0  # confidently wrong padding changes nothing
    torch.testing.assert_close(masked_bce(logits2, target, mask), want)


def test_config_validation_and_presets():
    with pytest.raises(ValueError, match="divisible"):
        TransitionConfig(hidden=30, n_heads=4)
    with pytest.raises(ValueError, match="unknown preset"):
        TransitionConfig.from_preset("huge")
    assert TransitionConfig.from_preset("quick").hidden < TransitionConfig.from_preset("paper").hidden
    cfg = TransitionConfig.from_preset("quick", epochs=2)
    assert TransitionConfig.from_json(json.loads(json.dumps(cfg.to_json()))) == cfg
    # the default config names its preset (a method of the same name once shadowed the field)
    assert TransitionConfig().preset == "paper" == TransitionConfig.from_preset("paper").preset
    assert TrainConfig().preset == "paper" and json.dumps(TrainConfig().to_json())


def test_code_width_is_the_learned_code_plus_the_location_bits_and_old_files_read_back():
    cfg = TransitionConfig.from_preset("quick", location_bits=9)  # valid before any effect model is known
    assert (cfg.code_bits, cfg.location_bits, cfg.bits) == (8, 9, 17)
    assert TransitionNet(cfg).pre[0].in_features == 17 + N_ACTIONS
    saved = cfg.to_json()
    assert saved["bits"] == 17 and TransitionConfig.from_json(saved) == cfg
    old = {k: v for k, v in saved.items() if k != "code_bits"}  # a file from when the config held the total only
    assert TransitionConfig.from_json(old) == cfg
    with pytest.raises(ValueError, match="not code_bits 8 \\+ location_bits 9"):
        TransitionConfig.from_json({**saved, "bits": 16})
    with pytest.raises(ValueError, match="more than 20"):
        TransitionConfig(code_bits=16, location_bits=9)
    with pytest.raises(ValueError, match="code_bits"):
        TransitionConfig(code_bits=0)


def test_copy_prior_makes_no_change_the_default():
    cfg = TransitionConfig.from_preset("quick", copy_prior=3.0)
    net = TransitionNet(cfg).eval()
    torch.nn.init.zeros_(net.post[-1].weight)
    torch.nn.init.zeros_(net.post[-1].bias)
    codes = torch.randint(0, 2, (4, 3, cfg.bits)).float()
    mask = torch.tensor([[True, True, False]] * 4)
    out = net(codes, mask, torch.arange(4))
    assert torch.equal(out.codes, codes * mask[..., None])
    assert torch.allclose(out.logits.abs(), 3.0 * mask[..., None].expand_as(codes).float())
    old = {k: v for k, v in cfg.to_json().items() if k != "copy_prior"}  # a config saved before copy_prior
    assert TransitionConfig.from_json(old).copy_prior == 0.0


def test_attention_rounds_extend_the_paper_net_and_keep_its_symmetry(tmp_path):
    with pytest.raises(ValueError, match="attention_rounds"):
        TransitionConfig(attention_rounds=0)
    assert TransitionConfig().attention_rounds == 1  # the paper's single attention layer, for old files
    assert TransitionConfig.from_preset("quick").attention_rounds == TransitionConfig.from_preset("paper").attention_rounds == 1
    one, three = _net(seed=5, attention_rounds=1), _net(seed=5, attention_rounds=3)
    assert not any(k.startswith("rounds.") for k in one.state_dict())
    assert sum(k.startswith("rounds.") for k in three.state_dict()) > 0
    g = torch.Generator().manual_seed(2)
    codes = torch.randint(0, 2, (36, 4, BITS), generator=g).float()
    mask = torch.tensor([[1, 1, 1, 0]] * 36).bool()
    act = torch.arange(36)
    with torch.no_grad():
        out = three(codes, mask, act).logits
        perm = torch.tensor([2, 0, 1, 3])
        torch.testing.assert_close(three(codes[:, perm], mask, act).logits, out[:, perm])  # equivariant
        noisy = codes.clone()
        noisy[:, 3] = 1 - noisy[:, 3]
        torch.testing.assert_close(three(noisy, mask, act).logits, out)  # padding ignored in every round
        # with its first round copied from the one-round net (same layer names), the further rounds still act
        three.load_state_dict({**three.state_dict(), **one.state_dict()})
        assert not torch.allclose(three(codes, mask, act).logits, one(codes, mask, act).logits)
    # a checkpoint written before attention_rounds existed loads as the paper's one-round net
    save_transition(tmp_path / "old.pt", one, {})
    blob = torch.load(tmp_path / "old.pt", map_location="cpu", weights_only=True)
    cfg = json.loads(blob["config"])
    del cfg["attention_rounds"]
    torch.save({**blob, "config": json.dumps(cfg)}, tmp_path / "old.pt")
    back, _ = load_transition(tmp_path / "old.pt")
    assert back.cfg.attention_rounds == 1
    with torch.no_grad():
        torch.testing.assert_close(back(codes, mask, act).logits, one(codes, mask, act).logits)


def test_rollout_chains_follow_episodes():
    episode = np.array([0, 0, 0, 1, 1, 2])
    step = np.array([0, 1, 2, 0, 1, 0])
    z = np.zeros((6, 1, BITS), np.float32)
    data = TransitionData(z, np.zeros(6, np.int64), z, np.ones((6, 1), bool), episode, step)
    assert rollout_chains(data, 1).tolist() == [[0], [1], [2], [3], [4], [5]]
    assert rollout_chains(data, 2).tolist() == [[0, 1], [1, 2], [3, 4]]
    assert rollout_chains(data, 3).tolist() == [[0, 1, 2]]
    assert rollout_chains(data, 4).shape == (0, 4)


# ------------------------------------------------------------------------------- data and training


def test_encoded_codes_chain_within_episodes(run):
    run_dir, data_dir, _ = run
    encoder, _ = load_effect_model(run_dir)
    data = load_split(data_dir, "train")
    td = build_transition_data(encoder, data)
    assert td.before.shape == data.pre_depth.shape[:2] + (encoder.cfg.bits,)
    assert set(np.unique(td.before).tolist()) <= {0.0, 1.0}
    assert not td.before[~td.mask].any() and not td.after[~td.mask].any()
    again = build_transition_data(encoder, data, batch_size=5)  # deterministic, batch-size independent
    np.testing.assert_array_equal(td.after, again.after)
    # the after-crops of step t are the before-crops of step t + 1: same codes
    pairs = rollout_chains(td, 2)
    assert len(pairs)
    np.testing.assert_array_equal(td.after[pairs[:, 0]], td.before[pairs[:, 1]])


def test_train_transition_writes_files_and_metrics(run):
    run_dir, data_dir, metrics = run
    m = json.loads((run_dir / METRICS_FILE).read_text())
    test = m["test"]
    # the reported test accuracies are those of the saved network on the test split, recomputed here
    net, _ = load_transition(run_dir / TRANSITION_FILE)
    encoder, _ = load_effect_model(run_dir)
    td = build_transition_data(encoder, load_split(data_dir, "test"))
    with torch.no_grad():
        pred = net(torch.from_numpy(td.before), torch.from_numpy(td.mask), torch.from_numpy(td.action)).codes.numpy()
    for name, guess in (("net", pred), ("copy", td.before)):
        got = test if name == "net" else test["copy_baseline"]
        bit_ok = guess == td.after
        obj_ok = bit_ok.all(-1)
        assert got["bit_accuracy"] == pytest.approx(bit_ok[td.mask].mean(), abs=1e-5), name
        assert got["object_accuracy"] == pytest.approx(obj_ok[td.mask].mean(), abs=1e-5), name
        assert got["scene_accuracy"] == pytest.approx((obj_ok | ~td.mask).all(-1).mean(), abs=1e-5), name
    assert m["n_samples"] == {"train": 40, "val": 4, "test": 4} and test["n"] == len(td) == 4
    assert set(test["rollout"]) == {str(n) for n in range(1, ROLLOUT_STEPS + 1)}
    for n, r in test["rollout"].items():  # one rollout per chain of n consecutive steps of a test episode
        assert r["n"] == len(rollout_chains(td, int(n))), n
    assert test["rollout"]["1"]["scene_accuracy"] == test["scene_accuracy"]
    assert [h["epoch"] for h in m["history"]] == [1, 2, 3]
    assert m["best_val_loss"] == pytest.approx(min(h["val_loss"] for h in m["history"]), abs=1e-5)
    assert len(m["history"]) == 3 and m["transition_config"]["preset"] == "quick"
    assert m["seed"] == 0 and m["data_fingerprint"] and "torch" in m["versions"]
    blob = torch.load(run_dir / TRANSITION_FILE, map_location="cpu", weights_only=True)
    assert json.loads(blob["config"])["bits"] == metrics["effect_model_bits"]


# ------------------------------------------------------------------------------- checkpoint refusals


def test_checkpoint_round_trip(tmp_path):
    net = _net(seed=3)
    save_transition(tmp_path / "t.pt", net, {"note": "x"})
    back, meta = load_transition(tmp_path / "t.pt")
    assert meta == {"note": "x"}
    for a, b in zip(net.state_dict().values(), back.state_dict().values()):
        torch.testing.assert_close(a, b)


def test_refuses_foreign_and_mismatched_files(run, tmp_path):
    run_dir, _, _ = run
    with pytest.raises(TransitionError, match="no transition model"):
        load_transition(tmp_path / "missing.pt")
    with pytest.raises(TransitionError, match="not a symlearn transition-model"):
        load_transition(run_dir / "best.pt")  # the effect model's checkpoint
    (tmp_path / "junk.pt").write_bytes(b"not a checkpoint at all")
    with pytest.raises(TransitionError, match="not a readable checkpoint"):
        load_transition(tmp_path / "junk.pt")
    blob = torch.load(run_dir / TRANSITION_FILE, map_location="cpu", weights_only=True)
    torch.save({**blob, "format_version": 99}, tmp_path / "future.pt")
    with pytest.raises(TransitionError, match="format 99"):
        load_transition(tmp_path / "future.pt")
    with pytest.raises(TransitionError, match="another transition config"):
        load_transition(run_dir / TRANSITION_FILE, expect_config=TransitionConfig.from_preset("paper"))
    with pytest.raises(TransitionError) as info:
        load_transition(tmp_path / "junk.pt")
    assert "\n" not in str(info.value)


def test_refuses_transition_of_another_effect_model(run, tmp_path):
    run_dir, _, _ = run
    other = tmp_path / "other"
    other.mkdir()
    (other / TRANSITION_FILE).write_bytes((run_dir / TRANSITION_FILE).read_bytes())
    blob = (run_dir / "best.pt").read_bytes()
    (other / "best.pt").write_bytes(blob[:-1] + bytes([blob[-1] ^ 1]))  # any change to the encoder's file
    with pytest.raises(TransitionError, match="another effect model"):
        LearnedTransition.from_run(other)
    assert LearnedTransition.from_run(run_dir).bits == load_effect_model(run_dir)[0].cfg.bits


# ------------------------------------------------------------------------------- planning interface


def test_learned_transition_protocol():
    m = LearnedTransition(_net(seed=4))
    rng = np.random.default_rng(0)
    codes = rng.integers(0, 1 << BITS, (36, 3))
    actions = np.arange(36)
    out = m(codes, actions)
    assert out.shape == (36, 3) and out.dtype == np.int64
    assert out.min() >= 0 and out.max() < 1 << BITS
    np.testing.assert_array_equal(out, m(codes, actions))  # deterministic
    np.testing.assert_array_equal(out[5:6], m(codes[5:6], actions[5:6]))  # batch independent
    perm = np.array([2, 0, 1])
    np.testing.assert_array_equal(m(codes[:, perm], actions), out[:, perm])  # permutation equivariant
    assert m(np.zeros((0, 3), np.int64), np.zeros(0, np.int64)).shape == (0, 3)


def test_scored_predictions_are_the_most_likely_codes_and_their_probability():
    net = _net(seed=4)
    m = LearnedTransition(net)
    rng = np.random.default_rng(1)
    codes, actions = rng.integers(0, 1 << BITS, (36, 3)), np.arange(36)
    nxt, nll = m.scored(codes, actions)
    np.testing.assert_array_equal(nxt, m(codes, actions))
    bits = torch.from_numpy(((codes[..., None] >> np.arange(BITS - 1, -1, -1)) & 1).astype(np.float32))
    with torch.no_grad():
        p = torch.sigmoid(net(bits, torch.ones(36, 3, dtype=torch.bool), torch.from_numpy(actions)).logits).double()
    # P(codes) is the product over objects and bits of the probability of the predicted bit
    expect = -torch.log(torch.where(p > 0.5, p, 1 - p)).sum((1, 2)).numpy()
    np.testing.assert_allclose(nll, expect, rtol=1e-5, atol=1e-6)
    assert nll.shape == (36,) and nll.dtype == np.float64 and (nll > 0).all()
    # a padded object adds nothing: scoring objects 0-1 with slot 2 masked equals scoring the 2-object scene
    from symlearn.symbolic.transition_model import predict_scored
    _, nll_pad = predict_scored(net, bits.numpy(), np.array([[1, 1, 0]] * 36, bool), actions)
    np.testing.assert_allclose(nll_pad, m.scored(codes[:, :2], actions)[1], rtol=1e-5)
    assert m.scored(np.zeros((0, 3), np.int64), np.zeros(0, np.int64))[1].shape == (0,)


def test_bit_probabilities_are_the_networks_sigmoids_and_agree_with_its_predictions():
    net = _net(seed=5)
    m = LearnedTransition(net)
    rng = np.random.default_rng(2)
    codes, actions = rng.integers(0, 1 << BITS, (36, 3)), np.arange(36)
    p = m.bit_probabilities(codes, actions)
    bits = torch.from_numpy(((codes[..., None] >> np.arange(BITS - 1, -1, -1)) & 1).astype(np.float32))
    with torch.no_grad():
        expect = torch.sigmoid(net(bits, torch.ones(36, 3, dtype=torch.bool), torch.from_numpy(actions)).logits)
    assert p.shape == (36, 3, BITS) and p.dtype == np.float64
    np.testing.assert_allclose(p, expect.double().numpy(), rtol=1e-6, atol=1e-7)
    # thresholded they are the network's prediction, and their product its probability
    nxt, nll = m.scored(codes, actions)
    weights = 1 << np.arange(BITS - 1, -1, -1)
    np.testing.assert_array_equal(((p >= 0.5) * weights).sum(-1), nxt)
    np.testing.assert_allclose(-np.log(np.maximum(p, 1 - p)).sum((1, 2)), nll, rtol=1e-5, atol=1e-6)
    assert m.bit_probabilities(np.zeros((0, 3), np.int64), np.zeros(0, np.int64)).shape == (0, 3, BITS)
    with pytest.raises(ValueError, match="action ids"):
        m.bit_probabilities(codes, actions + 1)


@pytest.mark.parametrize("codes, actions, match", [
    (np.zeros(3, np.int64), np.zeros(1, np.int64), "codes must be"),
    (np.zeros((2, 3), np.int64), np.zeros(3, np.int64), "codes must be"),
    (np.zeros((1, 3)), np.zeros(1, np.int64), "integers"),
    (np.full((1, 3), 256), np.zeros(1, np.int64), "codes must lie"),
    (np.zeros((1, 3), np.int64), np.array([36]), "action ids"),
])
def test_learned_transition_refuses_bad_input(codes, actions, match):
    with pytest.raises(ValueError, match=match):
        LearnedTransition(_net())(codes, actions)


def test_astar_runs_on_learned_transition():
    m = LearnedTransition(_net(seed=5))
    start = np.array([3, 200], np.int64)
    nxt = m(start[None].repeat(36, 0), np.arange(36))
    changed = np.flatnonzero((nxt != start).any(1))
    goal_state = nxt[changed[0]] if len(changed) else start
    res = plan_symbolic(m, start, SymbolicGoal(tuple(int(c) for c in goal_state)), uniform_cost=True, timeout_s=5)
    assert res.found and len(res.plan) <= 1
    assert res.predicted_states[-1] == tuple(int(c) for c in goal_state)


def test_encode_observation_of_live_scene(run, sim):
    run_dir, _, _ = run
    encoder, _ = load_effect_model(run_dir)
    sim.build([(ObjectType.CUBE, 3), (ObjectType.STICK, 4)])
    obs = sim.observe()
    codes = encode_observation(encoder, obs)
    assert codes.shape == (2,) and codes.dtype == np.int64
    assert codes.min() >= 0 and codes.max() < 1 << encoder.cfg.bits
    np.testing.assert_array_equal(codes, encode_observation(encoder, sim.observe()))


def test_fit_transition_keeps_the_best_epoch_of_a_custom_training_epoch():
    """train_epoch replaces the pass over pairs; validation still keeps the weights of the best epoch."""
    from symlearn.symbolic.transition_training import fit_transition

    rng = np.random.default_rng(0)
    z = rng.integers(0, 2, (24, 2, BITS)).astype(np.float32)
    data = TransitionData(z, rng.integers(0, 36, 24), z.copy(), np.ones((24, 2), bool), np.arange(24), np.zeros(24, np.int64))
    cfg = TransitionConfig.from_preset("quick", code_bits=BITS, epochs=4)
    calls = []

    def jolt(net, opt, gen, epoch):  # random steps: the validation loss goes up and down
        calls.append(epoch)
        with torch.no_grad():
            for p in net.parameters():
                p.add_(torch.randn(p.shape, generator=gen) * 0.3)
        return 1.0

    net, best, history = fit_transition(cfg, data, data, seed=0, train_epoch=jolt)
    assert calls == [0, 1, 2, 3] and [h["train_loss"] for h in history] == [1.0] * 4
    assert best == pytest.approx(min(h["val_loss"] for h in history), abs=1e-4)
    tensors = [torch.from_numpy(v) for v in (data.before, data.mask, data.action, data.after)]
    with torch.no_grad():
        kept = float(masked_bce(net(*tensors[:3]).logits, tensors[3], tensors[1]))
    assert kept == pytest.approx(best, rel=1e-5)
    assert history[-1]["val_loss"] > best + 1e-3  # the last epoch was not the best: its weights were not kept


# ------------------------------------------------------------------------------- extra transition data


def _td(n: int, k: int, episodes: list[int], seed: int) -> TransitionData:
    rng = np.random.default_rng(seed)
    mask = np.zeros((n, k), bool)
    mask[:, :2] = True
    bits = lambda: (rng.random((n, k, BITS)) < 0.5).astype(np.float32) * mask[..., None]  # noqa: E731
    return TransitionData(before=bits(), action=rng.integers(0, 36, n), after=bits(), mask=mask,
                          episode=np.asarray(episodes, np.int32), step=np.arange(n) % 3)


def test_concat_pads_objects_and_keeps_episodes_apart():
    a, b = _td(6, 3, [0, 0, 0, 1, 1, 1], 0), _td(3, 5, [0, 0, 0], 1)
    both = concat_transition_data([a, b])
    assert both.before.shape == (9, 5, BITS) and both.mask.shape == (9, 5)
    np.testing.assert_array_equal(both.before[:6, :3], a.before)
    assert not both.mask[:6, 3:].any() and not both.before[:6, 3:].any()
    np.testing.assert_array_equal(both.after[6:], b.after)
    assert both.episode.tolist() == [0, 0, 0, 1, 1, 1, 2, 2, 2]
    # a 3-step chain never joins the last episode of one part to the first of the next
    assert sorted(map(tuple, rollout_chains(both, 3).tolist())) == [(0, 1, 2), (3, 4, 5), (6, 7, 8)]
    with pytest.raises(ValueError, match="no transition data"):
        concat_transition_data([])


def test_extra_data_joins_training_and_is_tested_apart(tiny_run, tiny_run_copy, tiny_k45, capsys):
    extra = tiny_k45
    sizes = {s: len(load_split(extra, s).action) for s in ("train", "val", "test")}
    assert load_split(extra, "train").mask.shape[1] == 5
    out = cli_json("train-transition", "--run", tiny_run_copy, "--data", tiny_run.data, extra,
                   *TINY_TRANSITION_ARGS, "--quiet")
    m = json.loads((tiny_run_copy / METRICS_FILE).read_text())
    assert m["n_samples"] == {"train": 40 + sizes["train"], "val": 4 + sizes["val"], "test": 4}
    assert m["extra_data"] == [{"data": str(extra), "data_fingerprint": data_fingerprint(extra)}]
    # the saved network's accuracy on the extra set's 5-object test split, recomputed here
    net, meta = load_transition(tiny_run_copy / TRANSITION_FILE)
    assert meta["extra_data"] == m["extra_data"]
    encoder, _ = load_effect_model(tiny_run_copy)
    td = build_transition_data(encoder, load_split(extra, "test"))
    with torch.no_grad():
        pred = net(torch.from_numpy(td.before), torch.from_numpy(td.mask), torch.from_numpy(td.action)).codes.numpy()
    got = m["extra_test"][str(extra)]
    assert got["n"] == sizes["test"] == len(td)
    assert got["object_accuracy"] == pytest.approx((pred == td.after).all(-1)[td.mask].mean(), abs=1e-5)
    assert out["extra_test_rollout_scene_accuracy"][str(extra)]["1"] == got["scene_accuracy"]
    # the main test split is the same 4 samples as without extra data
    assert m["test"]["n"] == 4
    capsys.readouterr()
    rc, _ = cli("train-transition", "--run", tiny_run_copy, "--data", tiny_run.data,
                tiny_run.data, *TINY_TRANSITION_ARGS, "--quiet")
    assert rc != 0 and "must differ" in capsys.readouterr().err


# ------------------------------------------------------------------------------- outcome modes (a mixture m(z))


def _two_outcome_data(n: int = 400, seed: int = 0) -> tuple[TransitionData, np.ndarray, np.ndarray, np.ndarray]:
    """One start scene; action 0 leads to arrangement A (70%) or B (30%), which differ in 6 bits of object 0
    and 2 of object 1; every other action leaves the scene as it is. Returns the data, start, A and B bits."""
    rng = np.random.default_rng(seed)
    start = np.float32([[0, 0, 0, 0, 0, 0, 0, 1], [1, 0, 1, 0, 0, 0, 0, 0]])
    a = np.float32([[1, 1, 0, 0, 0, 0, 0, 1], [1, 0, 1, 0, 0, 0, 0, 0]])
    b = np.float32([[1, 0, 1, 1, 1, 1, 1, 1], [1, 0, 1, 0, 0, 0, 1, 1]])
    action = np.where(rng.random(n) < 0.5, 0, rng.integers(1, 36, n))
    after = np.where((action == 0)[:, None, None], np.where((rng.random(n) < 0.7)[:, None, None], a, b), start)
    data = TransitionData(np.repeat(start[None], n, 0), action.astype(np.int64), after.astype(np.float32),
                          np.ones((n, 2), bool), np.arange(n, dtype=np.int32), np.zeros(n, np.int64))
    return data, start, a, b


def test_modes_config_refuses_bad_counts_and_one_mode_is_the_paper_net():
    from symlearn.symbolic.transition_model import predict_modes, predict_scored, transition_loss
    for bad in (0, 17, 2.0):
        with pytest.raises(ValueError, match="modes="):
            TransitionConfig(modes=bad)
    net = _net(seed=2)
    assert not hasattr(net, "weight_head") and net.post[-1].out_features == BITS
    rng = np.random.default_rng(3)
    bits = (rng.random((36, 3, BITS)) < 0.5).astype(np.float32)
    mask, actions = np.ones((36, 3), bool), np.arange(36)
    states, nll = predict_modes(net, bits, mask, actions)
    codes, nll1 = predict_scored(net, bits, mask, actions)
    assert states.shape == (36, 1, 3, BITS) and np.array_equal(states[:, 0], codes)
    np.testing.assert_allclose(nll[:, 0], nll1, rtol=1e-6)
    t = [torch.from_numpy(v) for v in (bits, mask, actions)]
    with torch.no_grad():
        out = net(*t)
        assert float(transition_loss(out, t[0], t[1])) == pytest.approx(float(masked_bce(out.logits, t[0], t[1])))


def test_a_mixture_names_both_outcomes_whole_where_independent_bits_cannot(tmp_path):
    """Trained on a 70/30 choice between two arrangements many bits apart, two modes give both at about
    -log 0.7 and -log 0.3, and astar-outcomes' successors hold B; the paper's net only mixes bits."""
    from search.learned_astar import outcome_successors
    from symlearn.symbolic.transition_training import fit_transition

    data, start, a, b = _two_outcome_data()
    codes = lambda x: tuple(int(c) for c in (x * (1 << np.arange(BITS - 1, -1, -1))).sum(-1))  # noqa: E731
    nets = {m: fit_transition(TransitionConfig.from_preset("quick", code_bits=BITS, epochs=60, modes=m), data, data, seed=0)
            for m in (1, 2)}
    mix = LearnedTransition(nets[2][0])
    states, nll = mix.mode_outcomes(np.array([codes(start)]), np.array([0]))
    got = {tuple(s): float(x) for s, x in zip(states[0].tolist(), nll[0])}
    assert set(got) == {codes(a), codes(b)}
    assert got[codes(a)] == pytest.approx(-np.log(0.7), abs=0.15)
    assert got[codes(b)] == pytest.approx(-np.log(0.3), abs=0.2)
    assert tuple(mix(np.array([codes(start)]), np.array([0]))[0]) == codes(a)  # the likeliest mode answers
    p = mix.bit_probabilities(np.array([codes(start)]), np.array([0]))[0]  # the marginal: 0.3 on B's own bits
    assert p[0, 3] == pytest.approx(0.3, abs=0.1) and p[0, 1] == pytest.approx(0.7, abs=0.1)
    assert nets[2][1] < nets[1][1]  # the mixture fits the data better than independent bits
    succ = {(act, nxt) for act, nxt, _ in outcome_successors(mix, codes(start), 4, 0.05)}
    assert (0, codes(b)) in succ and (0, codes(a)) in succ
    paper = {(act, nxt) for act, nxt, _ in outcome_successors(LearnedTransition(nets[1][0]), codes(start), 4, 0.05)}
    assert (0, codes(a)) in paper and (0, codes(b)) not in paper  # 8 bits apart: no subset of 3 flips reaches B
    save_transition(tmp_path / "t.pt", nets[2][0], {})
    back, _ = load_transition(tmp_path / "t.pt")
    again, _ = LearnedTransition(back).mode_outcomes(np.array([codes(start)]), np.array([0]))
    assert back.cfg.modes == 2 and again.tolist() == states.tolist()


def test_train_transition_with_modes_plans_on_the_mixture(tiny_run, tiny_run_copy, tmp_path):
    """modes = 3 through the CLI: the config and checkpoint hold 3 modes, and astar-outcomes branches on them."""
    from search.learned_astar import mode_successors
    from symlearn.planning.execution import ObservedTransitions

    config = write_config(tmp_path / "modes3.toml", {"transition": {"modes": 3}})
    out = cli_json("train-transition", "--run", tiny_run_copy, "--data", tiny_run.data, "--preset", "quick",
                   "--config", config, "--quiet")
    want = recomputed_transition_accuracy(tiny_run_copy, tiny_run.data)  # the likeliest mode's predictions
    assert out["rollout_scene_accuracy"]["1"] == pytest.approx(want["scene_accuracy"], abs=1e-5)
    assert out["test"]["bit_accuracy"] == pytest.approx(want["bit_accuracy"], abs=1e-5)
    assert json.loads((tiny_run_copy / METRICS_FILE).read_text())["transition_config"]["modes"] == 3
    m = LearnedTransition.from_run(tiny_run_copy)
    assert m.modes == 3 and m.net.weight_head[-1].out_features == 3
    start = np.array([5, 77], np.int64)
    states, nll = m.mode_outcomes(start[None].repeat(36, 0), np.arange(36))
    assert states.shape == (36, 3, 2) and nll.shape == (36, 3) and (nll > 0).all()
    # every mode state is scored under the whole mixture, so no state is likelier than probability 1
    assert np.all(nll.min(1) >= 0) and np.allclose(m.scored(start[None].repeat(36, 0), np.arange(36))[1], nll.min(1))
    succ = mode_successors(m, tuple(start), 4, 0.05)
    assert succ and all(nxt != tuple(start) for _, nxt, _ in succ)
    # closed loop: an observed step has one outcome, the observed one, for certain
    memory = ObservedTransitions(m)
    memory.record(start, 7, (1, 2))
    st, ll = memory.mode_outcomes(start[None].repeat(36, 0), np.arange(36))
    assert (st[7] == [1, 2]).all() and (ll[7] == 0).all() and np.array_equal(st[8], states[8])
    _, target, _ = max(succ, key=lambda x: x[2])  # the least likely mode outcome the search may take
    res = plan_symbolic(m, start, SymbolicGoal(target), timeout_s=5, risk_weight=1.0, max_outcomes=4)
    assert res.found and len(res.plan) == 1 and res.predicted_states[-1] == target
