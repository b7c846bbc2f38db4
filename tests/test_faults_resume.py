"""Fault probes of resumed pipelines (issue 59): a rerun with other settings equals a fresh run.

`symlearn pipeline` into an existing OUT with another `--n`, `--epochs` or settings-file key must redo exactly
the stages whose config or inputs changed and the stages that read their outputs, and end with the files a fresh
run of those settings writes; a stage interrupted under the same settings still resumes (train from last.pt).
And a settings file's `[collect] seed` is the seed the data set is collected with.

What "the same files" means here (checked by _assert_same_outputs): every file under OUT is byte for byte the
fresh run's, except
- the fields that record wall times or dates (WALL_FIELDS), in the files that hold them (TIMED_JSON): the data
  sets' manifest.json ("updated"), run/metrics.json ("crops_per_s", "epoch_time_s"), run/transition_metrics.json
  ("encode_time_s", "wall_time_s"), run/pddl/lifted.json ("seconds", "distil_seconds") and run/benchmark.json
  (every "*time_s*" field); the rest of those files is equal;
- run/report.md and run/report.html, which show the benchmark's median planning time: equal but for that column;
- pipeline.json (each stage's wall time, start and finish dates, and hashes of the timed files): equal in its
  stages, their configs and the hashes of every other file;
- logs/, which every run appends to.
Model weights (best.pt, last.pt, transition.pt), data shards, problems, the PDDL domain and every other file
are byte-identical: training is seeded and deterministic at these sizes, and the checkpoints hold no wall times.
"""
from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from conftest import cli

PIPE_CONFIG = Path(__file__).resolve().parent / "pipe.toml"  # shards of 4 samples, a 2-epoch m(z)
STAGE_LINE = re.compile(r"^\[\d+/\d+\] (\S+) \.\.\. (skipped \(done\)|done in [\d.]+ s)$", re.M)
TIMED_JSON = ("data/manifest.json", "data_extra/manifest.json", "run/metrics.json", "run/transition_metrics.json",
              "run/pddl/lifted.json", "run/benchmark.json")
WALL_FIELDS = re.compile(r"^(updated|crops_per_s|seconds|distil_seconds)$|time_s")  # "timeout_s" is a setting
REPORTS = ("run/report.md", "run/report.html")
TIME_COLUMN = "median time (s)"


def _settings_file(path: Path, transition_epochs: int) -> Path:
    """tests/pipe.toml with m(z)'s epochs set to `transition_epochs`."""
    text = PIPE_CONFIG.read_text().replace("epochs = 2", f"epochs = {transition_epochs}")
    assert f"epochs = {transition_epochs}" in text
    path.write_text(text)
    return path


def _pipeline(out: Path, *args) -> dict[str, str]:
    """`symlearn pipeline --out OUT ARGS` (exit code 0): each stage -> "done" or "skipped"."""
    rc, text = cli("pipeline", "--out", out, *args)
    assert rc == 0, text
    return {m.group(1): m.group(2).split()[0] for m in STAGE_LINE.finditer(text)}


def _files(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*") if p.is_file() and p.parts[len(root.parts)] != "logs"}


def _untimed(value):
    """A JSON value with every wall-time or date field's value replaced by None (its key kept)."""
    if isinstance(value, dict):
        return {k: None if WALL_FIELDS.search(k) else _untimed(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_untimed(v) for v in value]
    return value


def _mask_time_column(text: str, html: bool) -> str:
    """The report with the cells of the benchmark table's median-time column replaced by '*'."""
    if html:
        def table(m: re.Match) -> str:
            column = re.findall(r"<th>(.*?)</th>", m.group(0)).index(TIME_COLUMN)

            def row(r: re.Match) -> str:
                cells = re.findall(r"<td>(.*?)</td>", r.group(0))
                cells[column] = "*"
                return "<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>"

            return re.sub(r"<tr><td>.*?</tr>", row, m.group(0))

        masked, tables = re.subn(r'<table data-table="benchmark">.*?</table>', table, text)
        assert tables == 1
        return masked
    lines, column, tables = text.split("\n"), None, 0
    for i, line in enumerate(lines):
        cells = line.split("|")
        if not line.startswith("|"):
            column = None
        elif column is None and TIME_COLUMN in [c.strip() for c in cells]:
            column, tables = [c.strip() for c in cells].index(TIME_COLUMN), tables + 1
        elif column is not None:
            lines[i] = "|".join(cells[:column] + ["*"] + cells[column + 1:])
    assert tables == 1
    return "\n".join(lines)


def _assert_same_outputs(a: Path, b: Path) -> None:
    """OUT `a` holds the files of OUT `b`, byte for byte but for the wall times and dates (module docstring)."""
    files = _files(a)
    assert files == _files(b)
    assert {"run/best.pt", "run/transition.pt", "run/pddl/lifted/domain.pddl", "data/shard_00000.npz"} <= files
    for rel in sorted(files - set(TIMED_JSON) - set(REPORTS) - {"pipeline.json"}):
        assert (a / rel).read_bytes() == (b / rel).read_bytes(), f"{rel} differs from the fresh run's"
    for rel in TIMED_JSON:
        assert _untimed(json.loads((a / rel).read_text())) == _untimed(json.loads((b / rel).read_text())), rel
    for rel in REPORTS:
        masked = [_mask_time_column((d / rel).read_text(), rel.endswith(".html")) for d in (a, b)]
        assert masked[0] == masked[1], f"{rel} differs from the fresh run's beyond the planning times"
    ra, rb = (json.loads((d / "pipeline.json").read_text())["stages"] for d in (a, b))
    assert list(ra) == list(rb)
    for name in ra:
        assert ra[name]["config"] == rb[name]["config"], name
        for kind in ("inputs", "outputs"):
            same = {r for r in ra[name][kind] if r not in TIMED_JSON and not r.startswith("run/report")}
            assert {r: ra[name][kind][r] for r in same} == {r: rb[name][kind][r] for r in same}, (name, kind)


def _args(n: int, epochs: int, config: Path) -> tuple:
    """The tiny pipeline's flags with `n` samples per set, `epochs` of the effect model, settings file `config`."""
    return ("--preset", "tiny", "--n", n, "--epochs", epochs, "--problems", 1, "--seed", 5, "--config", config)


def test_a_rerun_with_other_settings_redoes_what_changed_and_equals_a_fresh_run(tmp_path, tiny_preset, monkeypatch):
    import torch

    import symlearn.learning.training as training

    # on a CPU, as the pipeline trains there (in float32); a GPU's kernels need not be deterministic
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    names = tiny_preset.stage_names
    out = tmp_path / "pipe"
    config2, config3 = _settings_file(tmp_path / "t2.toml", 2), _settings_file(tmp_path / "t3.toml", 3)
    kept = ("collect", "collect-extra", "problems")  # what another --epochs or m(z) setting leaves alone
    assert _pipeline(out, *_args(24, 1, config2)) == dict.fromkeys(names, "done")

    # another --epochs: train and every stage reading best.pt (or what they wrote) again
    redone = {name: "skipped" if name in kept else "done" for name in names}
    assert _pipeline(out, *_args(24, 2, config2)) == redone

    # another settings-file key ([transition] epochs): m(z) and the stages after it that read its outputs
    later = names[names.index("train-transition"):]
    redone = {name: "done" if name in later and name not in kept else "skipped" for name in names}
    assert _pipeline(out, *_args(24, 2, config3)) == redone

    # another --n: the data sets change, so does all that reads them; interrupted in train after epoch 1 of 2
    save_epoch = training._save_epoch

    def save_then_interrupt(loop, epoch: int, *args) -> float:
        best = save_epoch(loop, epoch, *args)
        if epoch == 0:
            raise KeyboardInterrupt
        return best

    monkeypatch.setattr(training, "_save_epoch", save_then_interrupt)
    rc, text = cli("pipeline", "--out", out, *_args(30, 2, config3))
    assert rc == 130 and [m[0] for m in STAGE_LINE.findall(text)] == ["collect", "collect-extra"], text
    record = json.loads((out / "pipeline.json").read_text())["stages"]["train"]
    assert "outputs" not in record and record["config"]["epochs"] == 2 and (out / "run" / "last.pt").is_file()
    monkeypatch.setattr(training, "_save_epoch", save_epoch)

    # the same settings again: train resumes from last.pt (its second epoch only); the data sets stay
    resumed, resume = [], training._resume

    def spy(*args) -> tuple:
        res = resume(*args)
        resumed.append(res[0])  # the epoch it goes on from
        return res

    monkeypatch.setattr(training, "_resume", spy)
    assert _pipeline(out, *_args(30, 2, config3)) == {name: "skipped" if name in kept else "done" for name in names}
    assert resumed == [1]
    monkeypatch.setattr(training, "_resume", resume)

    # a fresh run of the last settings, in the same folder (paths are recorded), writes the same files
    out.rename(tmp_path / "rerun")
    assert _pipeline(out, *_args(30, 2, config3)) == dict.fromkeys(names, "done")
    _assert_same_outputs(tmp_path / "rerun", out)


def test_collect_seed_of_the_settings_file_is_the_data_sets_seed(tmp_path, tiny_preset):
    from symlearn.config_file import read_config_file
    from symlearn.pipeline import config_json, stage_configs
    from symlearn.pipeline_presets import PipelineSettings

    seeded = tmp_path / "seed5.toml"
    seeded.write_text(PIPE_CONFIG.read_text().replace("[collect]\n", "[collect]\nseed = 5\n"))
    assert read_config_file(seeded)["collect"]["seed"] == 5
    args = ("--preset", "tiny", "--n", 12, "--stop-after", "collect")
    _pipeline(tmp_path / "five", *args, "--config", seeded)
    _pipeline(tmp_path / "zero", *args, "--config", PIPE_CONFIG)
    five, zero = (json.loads((tmp_path / d / "data" / "manifest.json").read_text()) for d in ("five", "zero"))
    assert five["seed"] == five["settings"]["seed"] == 5 and zero["seed"] == 0
    assert [s["sha256"] for s in five["shards"]] != [s["sha256"] for s in zero["shards"]]  # other scenes
    record = json.loads((tmp_path / "five" / "pipeline.json").read_text())["stages"]["collect"]
    assert record["config"]["seed"] == 5

    # the extra set is drawn from that seed + 2; --seed, given, is every stage's seed over the file's
    configs = stage_configs(PipelineSettings(out=tmp_path / "x", preset="tiny", overrides=read_config_file(seeded)))
    assert (configs["collect"].seed, configs["collect-extra"].seed, configs["train"].seed) == (5, 7, 0)
    flagged = PipelineSettings(out=tmp_path / "x", preset="tiny", seed=3, overrides=read_config_file(seeded))
    assert {name: config_json(c).get("seed") for name, c in stage_configs(flagged).items()
            if name in ("collect", "collect-extra", "train")} == {"collect": 3, "collect-extra": 5, "train": 3}


def test_a_stage_starting_over_removes_only_its_own_files_inside_out(tmp_path):
    from symlearn.pipeline import clear_stage
    from symlearn.pipeline_presets import PRESETS
    from symlearn.pipeline_stages import pipeline_stages

    train = next(stage for stage in pipeline_stages(PRESETS["demo"]) if stage.name == "train")
    out, elsewhere = tmp_path / "pipe", tmp_path / "elsewhere"
    (out / "run").mkdir(parents=True)
    elsewhere.mkdir()
    for name in ("best.pt", "last.pt", "eval.json"):
        (out / "run" / name).write_text("x")
    (elsewhere / "metrics.json").write_text("{}")
    (out / "run" / "metrics.json").symlink_to(elsewhere / "metrics.json")
    assert sorted(clear_stage(out, train)) == ["run/best.pt", "run/last.pt", "run/metrics.json"]
    assert [p.name for p in (out / "run").iterdir()] == ["eval.json"]  # evaluate's file stays
    assert (elsewhere / "metrics.json").is_file()  # a link is removed, never what it points to

    # a run folder leading out of OUT is refused, in one line, before anything is removed
    (out / "run").rename(elsewhere / "run")
    (out / "run").symlink_to(elsewhere / "run")
    (elsewhere / "run" / "best.pt").write_text("x")
    with pytest.raises(ValueError, match=r"run/best.pt lies outside .*pipe") as info:
        clear_stage(out, train)
    assert "\n" not in str(info.value) and (elsewhere / "run" / "best.pt").is_file()


def test_train_refuses_to_resume_epochs_another_run_length_trained(tiny_data, tmp_path):
    """Without the pipeline's record (`symlearn train` again on its --out), a resume is refused where it would not
    train what the settings train: the cosine learning rates span all the epochs, so 2 of 2 are not 2 of 3."""
    from symlearn.learning.training import TrainConfig, TrainingError, train

    run, tiny = tmp_path / "run", dict(batch_size=8, bf16=False)
    train(tiny_data.path, run, TrainConfig.from_preset("quick", epochs=2, **tiny), show_progress=False)
    before = (run / "last.pt").read_bytes()
    with pytest.raises(TrainingError, match="2 epochs followed the learning rates of 2 epochs, not of 3"):
        train(tiny_data.path, run, TrainConfig.from_preset("quick", epochs=3, **tiny), show_progress=False)
    with pytest.raises(TrainingError, match="2 epochs are more than the 1 asked"):
        train(tiny_data.path, run, TrainConfig.from_preset("quick", epochs=1, **tiny), show_progress=False)
    assert (run / "last.pt").read_bytes() == before
