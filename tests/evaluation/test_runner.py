"""End-to-end grids: in-process, process pool and a local Ray give the same episodes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from explaindrive.cli.app import app
from explaindrive.env.actions import action_index
from explaindrive.evaluation.runner import EpisodeRecord, run_episode, run_grid
from explaindrive.evaluation.schema import SCHEMA_NAME, run_document, write_json
from explaindrive.evaluation.spec import parse_policy, plan_run
from tests.helpers import constant_policy

MAX_STEPS = 25  # [steps] short episodes keep the suite fast
SPLIT_S = 8.0  # [s] fast -> comfort switch of the merged run


def speed_change_policy(path: Path, change_mps: int, mode: str) -> Path:
    """A policy file whose greedy action is always ``change_mps``."""
    return constant_policy(path, action_index(change_mps), {"mode": mode, "episodes": 0})


@pytest.fixture(scope="module")
def policies(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("policies")
    return speed_change_policy(root / "fast.pt", 1, "fast"), speed_change_policy(
        root / "comfort.pt", 0, "comfort"
    )


@pytest.fixture(scope="module")
def plan(policies: tuple[Path, Path]):  # type: ignore[no-untyped-def]
    spec = parse_policy("merged", fast_path=policies[0], comfort_path=policies[1])
    return plan_run(spec, (0, 1), (0.5,), commands=f"fast:0-{SPLIT_S:g},comfort:{SPLIT_S:g}-",
                    max_steps=MAX_STEPS)  # fmt: skip


@pytest.fixture(scope="module")
def pool_records(plan) -> list[EpisodeRecord]:  # type: ignore[no-untyped-def]
    return run_grid(plan.episodes, workers=2)


def test_two_episode_grid_end_to_end(plan, pool_records: list[EpisodeRecord]) -> None:  # type: ignore[no-untyped-def]
    assert [(r.spec.seed, r.spec.traffic_level) for r in pool_records] == [(0, 0.5), (1, 0.5)]
    for rec in pool_records:
        n = int(SPLIT_S)
        # fast agent (+1 m/s per step) for 8 s, then the comfort agent holds the speed
        assert rec.commands[:n] == ("fast",) * n and set(rec.commands[n:]) == {"comfort"}
        # the road ahead is clear at level 0.5 for these seeds: no collision, full length
        assert rec.result.collisions == 0 and rec.result.steps == MAX_STEPS
        assert rec.speeds_mps[:n] == pytest.approx([float(i) for i in range(1, n + 1)])
        assert rec.speeds_mps[n:] == pytest.approx([float(n)] * (MAX_STEPS - n))
        assert rec.result.mean_speed_mps == pytest.approx((36 + 8 * (MAX_STEPS - n)) / MAX_STEPS)
        assert rec.result.steps == len(rec.speeds_mps)
        assert rec.result.mean_speed_mps == pytest.approx(sum(rec.speeds_mps) / rec.result.steps)
    # same seed, same numbers: rerun in this process
    assert run_episode(plan.episodes[0]) == pool_records[0]


def test_local_ray_equals_the_process_pool(plan, pool_records: list[EpisodeRecord]) -> None:  # type: ignore[no-untyped-def]
    ray = pytest.importorskip("ray")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        ray_records = run_grid(plan.episodes, use_ray=True)
    finally:
        ray.shutdown()
    assert ray_records == pool_records


def test_json_document(tmp_path: Path, plan, pool_records: list[EpisodeRecord]) -> None:  # type: ignore[no-untyped-def]
    path = write_json(tmp_path / "out" / "eval.json", [run_document(plan.name, pool_records)])
    doc = json.loads(path.read_text())
    assert doc["schema"] == SCHEMA_NAME and doc["version"] == 1
    run = doc["runs"][0]
    assert run["name"] == plan.name and run["seeds"] == [0, 1] and run["traffic_levels"] == [0.5]
    assert run["schedule"] == [[SPLIT_S, "comfort"]] and run["paper"] is None
    overall = run["aggregates"]["overall"]
    speeds = [r.result.mean_speed_mps for r in pool_records]
    assert overall["mean_speed_mps"] == pytest.approx(sum(speeds) / 2)
    assert run["aggregates"]["by_level"]["0.5"]["episodes"] == 2
    assert run["episodes"][1]["trace"]["speed_mps"] == list(pool_records[1].speeds_mps)
    assert run["episodes"][0]["metrics"]["steps"] == pool_records[0].result.steps
    with pytest.raises(ValueError, match="no episodes"):
        run_document("x", [])


def test_evaluate_cli(
    tmp_path: Path, policies: tuple[Path, Path], pool_records: list[EpisodeRecord]
) -> None:
    runner = CliRunner()
    out = tmp_path / "e.json"
    res = runner.invoke(app, [
        "evaluate", "merged", "--fast-policy", str(policies[0]), "--comfort-policy",
        str(policies[1]), "--seeds", "0", "--traffic", "0.5", "--commands",
        f"fast:0-{SPLIT_S:g},comfort:{SPLIT_S:g}-", "--max-steps", str(MAX_STEPS),
        "--workers", "1", "--json", str(out), "--figures", str(tmp_path / "figs"),
    ])  # fmt: skip
    assert res.exit_code == 0, res.output
    first = pool_records[0].result
    row = f"| merged (fast:0-8,comfort:8-) | {first.steps} | {first.mean_speed_mps:.3f} |"
    assert row in res.output
    assert json.loads(out.read_text())["runs"][0]["episodes"][0]["metrics"] == json.loads(
        json.dumps(first.as_dict())
    )
    # violations split by site, in the JSON (episode and aggregate) and the printed table
    doc = json.loads(out.read_text())["runs"][0]
    by_site = doc["episodes"][0]["metrics"]["violations_by_site"]
    assert sorted(by_site) == ["crossing", "free_road", "signal", "yield_junction"]
    assert sum(n["red_light_runs"] for n in by_site.values()) == first.red_light_runs
    assert sum(n["speeding_steps"] for n in by_site.values()) == first.speeding_steps
    assert doc["aggregates"]["overall"]["violations_by_site"] == by_site
    cells = [" / ".join(str(n) for n in by_site[site].values())
             for site in ("signal", "yield_junction", "crossing", "free_road")]  # fmt: skip
    assert f"| merged (fast:0-8,comfort:8-) | {' | '.join(cells)} |" in res.output
    assert (tmp_path / "figs" / "speed_profile.png").stat().st_size > 0
    assert (tmp_path / "figs" / "command_profile.png").stat().st_size > 0


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["krauss", "--seeds", "3-1"], "reversed"),
        (["krauss", "--traffic", "0.5,-1"], "> 0"),
        (["krauss", "--stop-schedule", "60-50"], "ends before it starts"),
        (["fast", "--fast-policy", "/nonexistent/p.pt"], "not found"),
        (["krauss", "--ray", "--ray-address", "auto"], "not both"),
    ],
)
def test_evaluate_cli_errors(args: list[str], message: str) -> None:
    res = CliRunner().invoke(app, ["evaluate", *args])
    assert res.exit_code == 2
    assert message in res.output


def test_report_document(tmp_path: Path, policies: tuple[Path, Path]) -> None:
    from explaindrive.evaluation.report import run_report
    from explaindrive.evaluation.report_plan import plan_report

    plan = plan_report(["merged"], (0,), (0.5,), merged_level=0.5, fast_path=policies[0],
                       comfort_path=policies[1], max_steps=MAX_STEPS)  # fmt: skip
    out = tmp_path / "docs" / "results.md"
    result = run_report(plan, out, workers=1, command_line="explaindrive report --test")
    rec = result.records["merged"][0]
    assert rec.commands == ("fast",) * MAX_STEPS  # the stop at 90 s lies beyond 25 steps
    md = result.markdown
    assert "Generated by `explaindrive report --test`" in md
    assert f"{rec.result.steps} steps, mean speed {rec.result.mean_speed_mps:.3f} m/s" in md
    assert "![merged_profile](figures/merged_profile.png)" in md
    assert (tmp_path / "docs" / "figures" / "merged_profile.png").is_file()


class _BuiltError(Exception):
    """Raised by the probe env once run_episode has built it."""


def test_a_network_is_evaluated_with_the_yellow_rule_it_was_trained_with(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    rules: list[str] = []

    class ProbeEnv:
        def __init__(self, config):  # type: ignore[no-untyped-def]
            rules.append(config.yellow_leader)
            raise _BuiltError

    monkeypatch.setattr("explaindrive.env.urban_drive.UrbanDriveEnv", ProbeEnv)
    for rule in ("always", "decided"):
        card = {"mode": "fast", "config": {"yellow_leader": rule}}
        path = constant_policy(tmp_path / f"{rule}.pt", action_index(0), card)
        spec = plan_run(parse_policy(str(path)), [0], [1.0], max_steps=MAX_STEPS).episodes[0]
        with pytest.raises(_BuiltError):
            run_episode(spec)
    assert rules == ["always", "decided"]


def test_a_network_drives_on_its_speed_estimate_under_the_episode_s_noise(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from explaindrive.agent.controller import MergedController
    from explaindrive.commands import Command

    began: list[float] = []
    real_begin = MergedController.begin

    def begin(self, speed_noise_sd_mps: float = 0.0) -> None:  # type: ignore[no-untyped-def]
        began.append(speed_noise_sd_mps)
        real_begin(self, speed_noise_sd_mps)

    class ProbeEnv:
        command = Command.FAST

        def __init__(self, config):  # type: ignore[no-untyped-def]
            self.config = config

        def reset(self, seed, options):  # type: ignore[no-untyped-def]
            return [0, 0.4, 13.9, 200.0, 0.0, 200.0, 0, 200.0], {}

        def step(self, action):  # type: ignore[no-untyped-def]
            raise _BuiltError

        def close(self) -> None:
            pass

    monkeypatch.setattr(MergedController, "begin", begin)
    monkeypatch.setattr("explaindrive.env.urban_drive.UrbanDriveEnv", ProbeEnv)
    path = constant_policy(tmp_path / "p.pt", action_index(0), {"mode": "fast"})
    for noise in ((0.0, 0.0), (2.0, 0.6)):
        spec = plan_run(parse_policy(str(path)), [0], [1.0], max_steps=MAX_STEPS,
                        obs_noise=noise).episodes[0]  # fmt: skip
        with pytest.raises(_BuiltError):
            run_episode(spec)
    assert began == [0.0, 0.6]


def test_after_reset_sees_the_env_once_the_ego_has_entered() -> None:
    from explaindrive.evaluation.spec import EpisodeSpec
    from explaindrive.sim.scenario.files import EGO_ID

    seen: list[tuple[float, float]] = []

    def hold(env) -> None:  # type: ignore[no-untyped-def]
        env.sumo.vehicle.setSpeedFactor(EGO_ID, 0.5)
        seen.append((env.sumo.vehicle.getSpeedFactor(EGO_ID), env.sumo.vehicle.getSpeed(EGO_ID)))

    spec = EpisodeSpec(parse_policy("krauss"), 0, 0.5, "fast", (), max_steps=30)
    record = run_episode(spec, after_reset=hold)
    assert seen == [(0.5, 0.0)]  # called once, before the first step: the ego stands at entry
    # held to half of 50 km/h (6.94 m/s), Krauss never drives faster
    assert max(record.speeds_mps) <= 0.5 * 50 / 3.6 + 1e-6
