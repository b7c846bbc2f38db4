"""Ray as an engine (symlearn.cluster): collection and benchmark rows as Ray tasks give the local engine's results.

One local 2-CPU Ray serves the module (started once, shut down after); collect and benchmark reuse a Ray this
process already started. The refusal without the extra runs without Ray: `import ray` is made to fail.
"""
from __future__ import annotations

import json
import sys

import pytest

from symlearn.cli.main import main
from symlearn.cluster import EngineError, as_finished, check_engine
from symlearn.data.dataset import load_manifest
from symlearn.planning import benchmark as bench
from symlearn.planning import benchmark_rows
from symlearn.planning.execution import ExecutionConfig
from symlearn.sim.collect import CollectConfig, collect, shard_name

CFG = CollectConfig(n=12, seed=7, shard_size=1)  # 12 one-sample shards: 10 train, 1 val, 1 test
TIMINGS = ("planning_time_s", "timings")  # what may differ between two runs of the same row


@pytest.fixture(scope="module")
def ray_cluster():
    import ray  # the extra is installed by `make test`: a missing Ray fails here rather than skipping

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    yield ray
    ray.shutdown()


@pytest.fixture(scope="module")
def local_set(tmp_path_factory):
    out = tmp_path_factory.mktemp("ray_local") / "set"
    collect(out, CFG, workers=1, show_progress=False)
    return out


def _shards(path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(path.glob("shard_*.npz"))}


def _entries(path) -> list[dict]:
    return load_manifest(path)["shards"]


def test_ray_collection_is_byte_identical_to_local(ray_cluster, local_set, tmp_path):
    out = tmp_path / "ray"
    m = collect(out, CFG, workers=2, show_progress=False, engine="ray")
    assert m["complete"] and m["n_shards"] == 12
    local = _shards(local_set)
    assert len(local) == 12 and _shards(out) == local
    assert _entries(out) == _entries(local_set)  # same checksums, sample counts and splits


def test_killed_ray_collection_resumes_to_the_same_bytes(ray_cluster, local_set, tmp_path, monkeypatch):
    out = tmp_path / "ray"
    import symlearn.sim.collect as collect_mod

    real_write, written = collect_mod._write_shard, []

    def dying_write(folder, index, arrays):  # the driver dies after writing 4 shards
        if len(written) == 4:
            raise KeyboardInterrupt
        written.append(index)
        return real_write(folder, index, arrays)

    monkeypatch.setattr(collect_mod, "_write_shard", dying_write)
    with pytest.raises(KeyboardInterrupt):
        collect(out, CFG, workers=2, show_progress=False, engine="ray")
    m = load_manifest(out, require_complete=False)
    assert not m["complete"] and sorted(d["index"] for d in m["shards"]) == sorted(written)
    assert set(_shards(out)) == {shard_name(i) for i in written}
    assert not list(out.glob(".*tmp*"))  # nothing half-written
    monkeypatch.setattr(collect_mod, "_write_shard", real_write)
    # a lost shard file is redone too; the shards finished before the kill are kept as they are
    (out / shard_name(written[0])).unlink()
    kept = {shard_name(i): (out / shard_name(i)).stat().st_mtime_ns for i in written[1:]}
    m = collect(out, CFG, workers=2, show_progress=False, engine="ray")
    assert m["complete"] and _shards(out) == _shards(local_set) and _entries(out) == _entries(local_set)
    assert {n: (out / n).stat().st_mtime_ns for n in kept} == kept


def test_cli_collect_on_ray(ray_cluster, local_set, tmp_path, capsys):
    out = tmp_path / "cli"
    (tmp_path / "shards.toml").write_text("[collect]\nshard_size = 1\n")
    rc = main(["collect", "--out", str(out), "--n", "12", "--seed", "7", "--config", str(tmp_path / "shards.toml"),
               "--workers", "2", "--ray", "--quiet"])
    assert rc == 0 and json.loads(capsys.readouterr().out)["shards"] == 12
    assert _shards(out) == _shards(local_set)


def test_as_finished_gives_every_result_and_raises_the_task_error_itself(ray_cluster):
    def square(x):  # defined here, so Ray ships it by value
        return x * x

    def invert(x):
        return 1 / x

    got = sorted(as_finished(ray_cluster, square, [(i, (i,)) for i in range(5)], window=2))
    assert got == [(i, i * i) for i in range(5)]
    with pytest.raises(ZeroDivisionError) as info:  # the task's own error, not Ray's wrapper with its traceback
        list(as_finished(ray_cluster, invert, [(i, (i,)) for i in range(3)], window=1))
    assert type(info.value) is ZeroDivisionError


def _without_timings(result: dict) -> dict:
    rows = [{k: v for k, v in r.items() if k not in TIMINGS} for r in result["rows"]]
    return {"rows": rows, **{k: result[k] for k in ("n_problems", "planners", "closed_loop", "transition_sha256",
                                                    "problems_sha256", "failure_causes", "goal_placement")}}


@pytest.fixture(scope="module")
def two_problems(tmp_path_factory, sim):
    from symlearn.problems.problem_generation import generate_problems

    out = tmp_path_factory.mktemp("ray_problems")
    generate_problems(out, 2, objects=(1, 2), length=(1, 2), seed=11, sim=sim)
    return out


def test_ray_benchmark_gives_the_local_rows_and_resumes(ray_cluster, tiny_run, two_problems, tmp_path):
    planners = ["astar", "rules-bfs"]
    kw = dict(closed_loop=True, timeout_s=5.0, show_progress=False)
    local = bench.benchmark(tiny_run.path, two_problems, planners, tmp_path / "local.json", **kw)
    out = tmp_path / "ray.json"
    remote = bench.benchmark(tiny_run.path, two_problems, planners, out, engine="ray", workers=2, **kw)
    assert len(remote["rows"]) == 2 * 2 * 2 and _without_timings(remote) == _without_timings(local)
    assert not benchmark_rows.rows_path(out).exists()
    # a killed run: its log holds some rows; the Ray engine runs only the others and ends with the same result
    log = benchmark_rows.rows_path(out)
    settings = bench._settings(tiny_run.path, [two_problems], benchmark_rows.load_sets([two_problems]), planners,
                               ExecutionConfig(closed_loop=True, timeout_s=5.0))
    first = benchmark_rows.RowLog(log, settings)
    first.open()
    keys = {p.label: p.key for p in benchmark_rows.load_sets([two_problems])}
    for r in local["rows"]:
        if r["planner"] == "astar":
            first.append((keys[r["problem"]], r["planner"], r["closed_loop"]), dict(r, message="kept from the first run"))
    first.close()
    resumed = bench.benchmark(tiny_run.path, two_problems, planners, out, engine="ray", workers=2, **kw)
    assert _without_timings(resumed)["rows"] == [dict(r, message="kept from the first run") if r["planner"] == "astar"
                                                 else r for r in _without_timings(local)["rows"]]


def test_engine_ray_without_the_extra_is_refused_in_one_line(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` now raises ImportError
    out = tmp_path / "never"
    rc = main(["collect", "--out", str(out), "--n", "12", "--ray", "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and err == ["symlearn collect: error: --ray needs Ray, which is not installed; "
                               "pip install symlearn[ray]"]
    assert not out.exists()  # refused before any work
    rc = main(["benchmark", "--run", str(tmp_path / "run"), "--problems", str(tmp_path), "--out",
               str(tmp_path / "b.json"), "--ray", "auto"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and err[0].endswith("pip install symlearn[ray]")
    with pytest.raises(RuntimeError, match=r"pip install symlearn\[ray\]"):
        collect(out, CFG, engine="ray")


def test_engine_settings_refused_where_they_do_not_apply(tmp_path, capsys):
    with pytest.raises(EngineError, match="needs the ray engine"):
        check_engine("local", "10.0.0.1:6379")
    with pytest.raises(EngineError, match="unknown engine 'dask'"):
        check_engine("dask")
    rc = main(["benchmark", "--run", str(tmp_path), "--problems", str(tmp_path), "--out", str(tmp_path / "b.json"),
               "--workers", "2"])
    assert rc == 2 and "add --ray" in capsys.readouterr().err
    with pytest.raises(SystemExit) as info:
        main(["collect", "--out", str(tmp_path / "x"), "--engine", "ray"])  # the flag is --ray
    assert info.value.code == 2
    assert not (tmp_path / "x").exists()
