"""The subprocess vector env."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from explaindrive.agent.vec_env import SubprocVecEnv, SyncVecEnv, make_vec_env, reset, step
from tests.agent.fake_drive_env import FakeDriveEnv


def _broken_env() -> FakeDriveEnv:
    raise OSError("no SUMO here")


def test_subprocess_and_sync_envs_agree() -> None:
    factory = functools.partial(FakeDriveEnv, max_steps=5)
    procs = make_vec_env(factory, 2)
    sync = make_vec_env(factory, 2, subprocess=False)
    assert isinstance(procs, SubprocVecEnv) and isinstance(sync, SyncVecEnv)
    try:
        opts = [{"command": "fast"}, {"command": "stop"}]
        a, _ = reset(procs, [0, 1], [3, 4], opts)
        b, _ = reset(sync, [0, 1], [3, 4], opts)
        assert np.array_equal(a, b) and a[1, 0] == 2.0
        actions = np.array([6, 0])
        step_a, step_b = step(procs, [0, 1], actions), step(sync, [0, 1], actions)
        for x, y in zip(step_a[:4], step_b[:4], strict=True):
            assert np.array_equal(x, y)
        # only env 1 steps: env 0 keeps its state
        obs, *_ = step(procs, [1], np.array([3]))
        assert obs.shape == (1, 8)

    finally:
        procs.close()
        sync.close()


def test_worker_errors_name_the_env() -> None:
    with pytest.raises(RuntimeError, match=r"env worker 0 failed:[\s\S]*no SUMO here"):
        SubprocVecEnv([_broken_env])
    envs = SubprocVecEnv([functools.partial(FakeDriveEnv, max_steps=5)])
    try:
        reset(envs, [0], [0], [{}])
        with pytest.raises(RuntimeError, match="outside the action space"):
            step(envs, [0], np.array([9]))
    finally:
        envs.close()


def test_workers_return_only_the_asked_info_keys() -> None:
    factory = functools.partial(FakeDriveEnv, max_steps=5)
    for vec in (make_vec_env(factory, 2, info_keys=("speed_mps",)),
                make_vec_env(factory, 1, info_keys=("speed_mps",))):  # fmt: skip
        try:
            ids = list(range(vec.num_envs))
            reset(vec, ids, ids, [{}] * len(ids))
            vec.step_async(ids, np.full(len(ids), 6))  # +3 m/s
            *_, infos = vec.step_wait(ids)
            assert all(set(info) == {"speed_mps"} for info in infos)
        finally:
            vec.close()
