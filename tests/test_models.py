import pytest
import torch

from symlearn.learning.models import AttentiveDeepSym, ModelConfig, gumbel_sigmoid, masked_mse

CFG = ModelConfig.from_preset("quick")


def _batch(b=4, k=3, s=64, seed=0):
    g = torch.Generator().manual_seed(seed)
    x = torch.rand(b, k, 3, s, s, generator=g) * 1.5
    mask = torch.ones(b, k, dtype=torch.bool)
    mask[0, 1:] = False
    mask[1, 2] = False
    return x, mask, torch.randint(0, 36, (b,), generator=g)


@pytest.mark.parametrize("attention", [True, False])
def test_padding_does_not_change_real_objects(attention):
    model = AttentiveDeepSym(ModelConfig.from_preset("quick", attention=attention)).eval()
    x, mask, a = _batch()
    out1 = model(x, mask, a)
    x2 = x.clone()
    x2[~mask] = torch.rand_like(x2[~mask]) * 9  # garbage in padded slots
    out2 = model(x2, mask, a)
    torch.testing.assert_close(out1.effect[mask], out2.effect[mask])
    assert torch.all(out1.effect[~mask] == 0) and torch.all(out1.codes[~mask] == 0)


def test_attention_lets_objects_influence_each_other():
    """Another object's code changes an object's predicted effect only when attention is on."""
    torch.manual_seed(0)
    mask = torch.ones(1, 3, dtype=torch.bool)
    codes = torch.tensor([[[0, 1, 0, 1, 1, 0, 0, 1], [1, 1, 0, 0, 1, 0, 1, 0], [0, 0, 0, 0, 0, 0, 0, 0]]]).float()
    other = codes.clone()
    other[0, 1] = 1 - other[0, 1]  # flip every bit of object 1
    a = torch.tensor([7])
    att = AttentiveDeepSym(CFG).eval()
    assert not torch.allclose(att.decode(codes, mask, a)[0, 0], att.decode(other, mask, a)[0, 0])
    base = AttentiveDeepSym(ModelConfig.from_preset("quick", attention=False)).eval()
    torch.testing.assert_close(base.decode(codes, mask, a)[0, 0], base.decode(other, mask, a)[0, 0])


def test_masked_mse_ignores_padding():
    pred = torch.zeros(2, 3, 3)
    target = torch.ones(2, 3, 3)
    mask = torch.tensor([[True, False, False], [True, True, False]])
    target[~mask] = 1000.0
    assert masked_mse(pred, target, mask).item() == pytest.approx(1.0)


def test_gumbel_sigmoid_straight_through_and_deterministic_eval():
    logits = torch.tensor([[-3.0, -0.1, 0.2, 4.0]], requires_grad=True)
    z = gumbel_sigmoid(logits, 1.0, training=True, generator=torch.Generator().manual_seed(0))
    assert set(z.detach().unique().tolist()) <= {0.0, 1.0}
    (z * torch.arange(4.0)).sum().backward()
    assert logits.grad is not None and torch.all(logits.grad[0, 1:] > 0)  # gradient flows through the sample
    ev = gumbel_sigmoid(logits.detach(), 1.0, training=False)
    assert ev.tolist() == [[0.0, 0.0, 1.0, 1.0]]


def test_encoder_gets_gradients_through_binary_codes():
    model = AttentiveDeepSym(CFG).train()
    x, mask, a = _batch(b=8)
    out = model(x, mask, a, generator=torch.Generator().manual_seed(1))
    masked_mse(out.effect, torch.randn_like(out.effect), mask).backward()
    g = model.encoder.proj.weight.grad
    assert g is not None and g.abs().sum() > 0


@pytest.mark.parametrize("bad", ["shape", "action"])
def test_bad_inputs_refused(bad):
    model = AttentiveDeepSym(CFG).eval()
    x, mask, a = _batch()
    if bad == "shape":
        with pytest.raises(ValueError, match="crops must be"):
            model(x[:, :, :2], mask, a)
    else:
        with pytest.raises(ValueError, match="unknown action id"):
            model(x, mask, torch.tensor([0, 1, 2, 36]))


def test_config_validation_and_presets():
    with pytest.raises(ValueError, match="divisible by n_heads"):
        ModelConfig(d_model=100, n_heads=8)
    with pytest.raises(ValueError, match="unknown preset"):
        ModelConfig.from_preset("huge")
    p = ModelConfig.from_preset("paper")
    assert p.conv_channels == (64, 128, 256, 512) and p.n_layers == 4 and p.decoder_hidden == (256, 256, 256)
    assert ModelConfig.from_json(p.to_json()) == p


def test_dynamics_head_predicts_next_codes_from_the_codes_before():
    from symlearn.learning.models import code_prediction_loss

    cfg = ModelConfig.from_preset("quick", dynamics_head=True)
    model = AttentiveDeepSym(cfg).train()
    mask = torch.tensor([[1, 1, 0], [1, 0, 0]]).bool()
    crops, post = torch.rand(2, 3, 3, 32, 32), torch.rand(2, 3, 3, 32, 32)
    out = model(crops, mask, torch.tensor([0, 35]), post_crops=post)
    assert out.next_logits.shape == out.next_codes.shape == (2, 3, cfg.bits)
    assert float(out.next_logits[~mask].abs().sum()) == 0.0  # padded slots predict nothing
    assert out.post_logits.shape == out.logits.shape
    loss = code_prediction_loss(out.next_logits, out.next_codes, mask)
    # equals binary cross-entropy with the post codes as targets, over the real objects
    ref = torch.nn.functional.binary_cross_entropy_with_logits(out.next_logits[mask], out.next_codes[mask].detach())
    assert float(loss) == pytest.approx(float(ref), rel=1e-5)
    # the gradient reaches the encoder through the codes before only: the targets are detached
    g_pre = torch.autograd.grad(loss, out.codes, retain_graph=True)[0]
    assert g_pre.abs().sum() > 0 and not out.next_codes.detach().requires_grad
    assert torch.autograd.grad(loss, out.post_logits, retain_graph=True, allow_unused=True)[0] is None
    # without post crops only effects and codes come back; without a head no next-code logits
    assert model(crops, mask, torch.tensor([0, 35])).next_logits is None
    plain = AttentiveDeepSym(ModelConfig.from_preset("quick"))(crops, mask, torch.tensor([0, 1]), post_crops=post)
    assert plain.next_logits is None and plain.next_codes.shape == (2, 3, cfg.bits)
    with pytest.raises(ValueError, match="post_crops"):
        model(crops, mask, torch.tensor([0, 35]), post_crops=post[:, :2])


def test_masked_mse_weights_objects():
    pred, target = torch.zeros(1, 2, 3), torch.ones(1, 2, 3)
    target[0, 1] = 2.0  # object 1 errs by 2 per axis (squared 4), object 0 by 1
    mask = torch.tensor([[True, True]])
    assert float(masked_mse(pred, target, mask)) == pytest.approx((1 + 4) / 2)
    assert float(masked_mse(pred, target, mask, torch.tensor([[1.0, 3.0]]))) == pytest.approx((1 + 12) / 2)


def test_distinct_loss_asks_one_decisive_differing_bit_per_pair_of_real_objects():
    from symlearn.learning.models import code_distinct_loss

    mask = torch.tensor([[True, True, True, False]])
    apart = torch.tensor([[[3.0, 1.0], [-2.5, 1.0], [2.0, -4.0], [3.0, 1.0]]])  # slot 3 is padding, equal to object 0
    # pairs: (0, 1) bit 0 separated by min(3, 2.5); (0, 2) bit 1 by min(1, 4) = 1; (1, 2) bit 0 by 2
    assert float(code_distinct_loss(apart, mask, 1.0)) == 0.0
    assert float(code_distinct_loss(apart, mask, 2.0)) == pytest.approx(1.0 / 3, rel=1e-6)  # pair (0, 2) pays 1
    same = torch.tensor([[[1.0, -1.0], [1.0, -1.0], [-3.0, 2.0], [0.0, 0.0]]])  # objects 0 and 1 share their code
    # pair (0, 1): best bit separates by min(1, -1) = -1 -> pays 1 + 1; (0, 2) and (1, 2) by min(1, 2) = 1 on bit 1
    assert float(code_distinct_loss(same, mask, 1.0)) == pytest.approx(2.0 / 3, rel=1e-6)
    logits = same.clone().requires_grad_(True)
    code_distinct_loss(logits, mask, 1.0).backward()
    assert logits.grad[0, 3].abs().sum() == 0  # padding is never pushed
    assert logits.grad[0, 0].abs().sum() > 0 and logits.grad[0, 1].abs().sum() > 0


def test_stability_loss_is_zero_only_for_agreeing_decisive_bits_of_still_objects():
    from symlearn.learning.models import code_stability_loss

    still = torch.tensor([[True, False]])
    agree = torch.tensor([[[3.0, -2.5], [0.1, 0.1]]])  # object 0: same side, beyond the margin of 2
    assert float(code_stability_loss(agree, agree.clone(), still, 2.0)) == 0.0  # object 1 is not still: ignored
    flip = agree.clone()
    flip[0, 0, 0] = -3.0  # bit 0 of the still object flips sign: the sum is 0 (side +1), the -3 pays 2 + 3
    assert float(code_stability_loss(agree, flip, still, 2.0)) == pytest.approx(5.0 / 2, rel=1e-6)
    flip[0, 0, 0] = -4.0  # now the sum says 0: the +3 pays 2 + 3, the -4 nothing
    assert float(code_stability_loss(agree, flip, still, 2.0)) == pytest.approx(5.0 / 2, rel=1e-6)
    weak = agree.clone()
    weak[0, 0, 1] = -1.0  # agrees but only 1 from 0: pays 1 on one side
    assert float(code_stability_loss(agree, weak, still, 2.0)) == pytest.approx(1.0 / 2, rel=1e-6)
    pre = agree.clone().requires_grad_(True)
    code_stability_loss(pre, flip, still, 2.0).backward()
    assert pre.grad[0, 1].abs().sum() == 0 and pre.grad[0, 0].abs().sum() > 0  # only still objects are pushed


def test_the_action_per_object_reaches_only_the_held_objects_token():
    """With action_per_object the held object's token alone carries the action: without attention the others'
    effects cannot depend on it (the DeepSym baseline then cannot know a rider moves), the held one's do; a
    model that takes the action per object refuses a call without the held index."""
    torch.manual_seed(0)
    base = AttentiveDeepSym(ModelConfig.from_preset("quick", attention=False, action_per_object=True)).eval()
    att = AttentiveDeepSym(ModelConfig.from_preset("quick", action_per_object=True)).eval()
    codes = (torch.rand(1, 3, 8) > 0.5).float()
    mask = torch.ones(1, 3, dtype=torch.bool)
    held = torch.tensor([1])
    e1, e2 = (base.decode(codes, mask, torch.tensor([a]), held) for a in (3, 20))
    torch.testing.assert_close(e1[0, [0, 2]], e2[0, [0, 2]])  # the others do not see the action
    assert not torch.allclose(e1[0, 1], e2[0, 1])  # the held object does
    a1, a2 = (att.decode(codes, mask, torch.tensor([a]), held) for a in (3, 20))
    assert not torch.allclose(a1[0, 0], a2[0, 0])  # with attention the others learn of it from the held one
    nothing = base.decode(codes, mask, torch.tensor([3]), torch.tensor([-1]))
    torch.testing.assert_close(nothing, base.decode(codes, mask, torch.tensor([20]), torch.tensor([-1])))
    with pytest.raises(ValueError, match="per object"):
        att.decode(codes, mask, torch.tensor([3]))
