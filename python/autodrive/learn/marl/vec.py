"""Shared-parameter vectorisation: K copies of the N-agent parallel environment become one
stable-baselines3 VecEnv of K x N single-agent slots, so one policy acts for every car. A car
whose episode ended waits for the others as a "dead" slot: zero observation, reward 0, done
every step (1-step episodes that bootstrap nothing), as SuperSuit's black_death does. The
copies run in this process (workers=1), spread over worker processes (workers > 1, pipes), or
over Ray actors (ray_address: a cluster that `ray start --head` started; one actor per worker).
Episode seeds come from the base seed, so a run is repeatable for a given K and workers."""

from __future__ import annotations

import multiprocessing as mp
from collections.abc import Sequence
from dataclasses import dataclass
from multiprocessing.connection import Connection
from typing import Any

import numpy as np
import numpy.typing as npt
from stable_baselines3.common.vec_env.base_vec_env import VecEnv, VecEnvObs, VecEnvStepReturn

from autodrive.learn.marl.env import STEER_RATE_PENALTY, MarlIntersectionEnv

SEED_STRIDE = 1_000_003  # episode e of copy k: base + k * SEED_STRIDE + e


@dataclass(frozen=True)
class EnvSpec:
    """What each copy is (picklable, for the worker processes)."""

    cars: int
    action_mode: str = "discrete"
    shield: bool = False
    shaping: str = "progress"
    steer_rate_penalty: float = STEER_RATE_PENALTY

    def make(self) -> MarlIntersectionEnv:
        return MarlIntersectionEnv(
            cars=self.cars,
            action_mode=self.action_mode,
            shield=self.shield,
            shaping=self.shaping,
            steer_rate_penalty=self.steer_rate_penalty,
        )


class EnvGroup:
    """Some copies of the environment and their slots' bookkeeping (one per process)."""

    def __init__(self, spec: EnvSpec, copies: Sequence[int], base_seed: int) -> None:
        self.envs = [spec.make() for _ in copies]
        self.copies = list(copies)
        self.base_seed = base_seed
        self.episode = [0] * len(copies)
        self.n = spec.cars
        self.returns = np.zeros((len(copies), self.n))
        self.lengths = np.zeros((len(copies), self.n), dtype=np.int64)
        self.dim = self.envs[0].observation_space("nigel1").shape[0]  # type: ignore[index]

    def _reset(self, j: int) -> npt.NDArray[np.float32]:
        env = self.envs[j]
        seed = self.base_seed + self.copies[j] * SEED_STRIDE + self.episode[j]
        self.episode[j] += 1
        obs, _ = env.reset(seed=seed)
        self.returns[j] = 0.0
        self.lengths[j] = 0
        return np.stack([obs[a] for a in env.possible_agents])

    def reset(self) -> npt.NDArray[np.float32]:
        return np.concatenate([self._reset(j) for j in range(len(self.envs))])

    def step(self, actions: npt.NDArray[Any]) -> tuple[Any, Any, Any, list[dict[str, Any]]]:
        obs = np.zeros((len(self.envs) * self.n, self.dim), dtype=np.float32)
        rew = np.zeros(len(self.envs) * self.n, dtype=np.float32)
        done = np.zeros(len(self.envs) * self.n, dtype=bool)
        infos: list[dict[str, Any]] = [{} for _ in range(len(self.envs) * self.n)]
        for j, env in enumerate(self.envs):
            live = list(env.agents)
            acts = {a: actions[j * self.n + env.possible_agents.index(a)] for a in live}
            o, r, te, tr, _ = env.step(acts)
            for i, a in enumerate(env.possible_agents):
                s = j * self.n + i
                if a not in live:  # dead slot
                    done[s] = True
                    continue
                rew[s] = r[a]
                self.returns[j, i] += r[a]
                self.lengths[j, i] += 1
                if te[a] or tr[a]:
                    done[s] = True
                    infos[s] = {
                        "terminal_observation": o[a],
                        "TimeLimit.truncated": bool(tr[a] and not te[a]),
                        "episode": {"r": float(self.returns[j, i]), "l": int(self.lengths[j, i])},
                        "outcome": env.stats["outcome"][i],
                    }
                else:
                    obs[s] = o[a]
            if not env.agents:
                stats = env.stats
                first = j * self.n
                infos[first]["env_episode"] = {
                    "success": all(x == "goal" for x in stats["outcome"]),
                    "collisions": sum(x == "collision" for x in stats["outcome"]),
                }
                obs[first : first + self.n] = self._reset(j)
        return obs, rew, done, infos

    def close(self) -> None:
        for e in self.envs:
            e.close()


def _worker(conn: Connection, spec: EnvSpec, copies: list[int], base_seed: int) -> None:
    group = EnvGroup(spec, copies, base_seed)
    try:
        while True:
            cmd, data = conn.recv()
            if cmd == "reset":
                conn.send(group.reset())
            elif cmd == "step":
                conn.send(group.step(data))
            elif cmd == "close":
                break
    except (EOFError, KeyboardInterrupt):
        pass
    finally:
        group.close()
        conn.close()


class GroupActor:
    """An EnvGroup in a Ray actor (the same calls as the pipe workers' commands)."""

    def __init__(self, spec: EnvSpec, copies: list[int], base_seed: int) -> None:
        self.group = EnvGroup(spec, copies, base_seed)

    def reset(self) -> npt.NDArray[np.float32]:
        return self.group.reset()

    def step(self, actions: npt.NDArray[Any]) -> tuple[Any, Any, Any, list[dict[str, Any]]]:
        return self.group.step(actions)

    def close(self) -> None:
        self.group.close()


class MarlVecEnv(VecEnv):
    """copies x spec.cars slots for stable-baselines3, on `workers` processes (or Ray actors on
    the cluster at ray_address)."""

    def __init__(
        self, spec: EnvSpec, copies: int, workers: int = 1, seed: int = 0, ray_address: str = ""
    ) -> None:
        if copies < 1 or not 1 <= workers <= copies:
            raise ValueError(f"copies {copies}, workers {workers}: need 1 <= workers <= copies")
        probe = spec.make()
        obs_space, act_space = probe.observation_space("nigel1"), probe.action_space("nigel1")
        probe.close()
        super().__init__(copies * spec.cars, obs_space, act_space)
        self.spec = spec
        split = np.array_split(np.arange(copies), workers)
        self.slot_split = [len(s) * spec.cars for s in split]
        self.local: EnvGroup | None = None
        self.conns: list[Connection] = []
        self.procs: list[Any] = []
        self.actors: list[Any] = []
        self.pending: list[Any] = []
        if ray_address:
            import ray

            remote = ray.remote(num_cpus=1)(GroupActor)
            self.actors = [remote.remote(spec, [int(c) for c in part], seed) for part in split]
        elif workers == 1:
            self.local = EnvGroup(spec, list(range(copies)), seed)
        else:
            ctx = mp.get_context("spawn")  # no fork of a process with torch threads
            for part in split:
                parent, child = ctx.Pipe()
                p = ctx.Process(
                    target=_worker, args=(child, spec, [int(c) for c in part], seed), daemon=True
                )
                p.start()
                child.close()
                self.conns.append(parent)
                self.procs.append(p)
        self._actions: npt.NDArray[Any] | None = None

    def reset(self) -> VecEnvObs:
        if self.local is not None:
            return self.local.reset()
        if self.actors:
            import ray

            parts = ray.get([a.reset.remote() for a in self.actors])
            joined: npt.NDArray[np.float32] = np.concatenate(parts)
            return joined
        for c in self.conns:
            c.send(("reset", None))
        obs: npt.NDArray[np.float32] = np.concatenate([c.recv() for c in self.conns])
        return obs

    def step_async(self, actions: npt.NDArray[Any]) -> None:
        self._actions = np.asarray(actions)
        start = 0
        for k, n in enumerate(self.slot_split):
            part = self._actions[start : start + n]
            start += n
            if self.actors:
                self.pending.append(self.actors[k].step.remote(part))
            elif self.conns:
                self.conns[k].send(("step", part))

    def step_wait(self) -> VecEnvStepReturn:
        assert self._actions is not None
        if self.local is not None:
            parts = [self.local.step(self._actions)]
        elif self.actors:
            import ray

            parts = ray.get(self.pending)
            self.pending = []
        else:
            parts = [c.recv() for c in self.conns]
        obs = np.concatenate([p[0] for p in parts])
        rew = np.concatenate([p[1] for p in parts])
        done = np.concatenate([p[2] for p in parts])
        infos = [i for p in parts for i in p[3]]
        return obs, rew, done, infos

    def close(self) -> None:
        if self.local is not None:
            self.local.close()
        if self.actors:
            import ray

            ray.get([a.close.remote() for a in self.actors])
            for a in self.actors:
                ray.kill(a)
            self.actors = []
        for c in self.conns:
            try:
                c.send(("close", None))
            except (BrokenPipeError, OSError):
                pass
        for p in self.procs:
            p.join(timeout=10)
            if p.is_alive():
                p.terminate()

    # The rest of the VecEnv interface: nothing here uses gym wrappers or per-slot attributes.
    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        return [getattr(self.spec, attr_name, None)] * self.num_envs

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        raise AttributeError(f"MarlVecEnv: set_attr('{attr_name}') is not supported")

    def env_method(self, method_name: str, *args: Any, indices: Any = None, **kw: Any) -> list[Any]:
        raise AttributeError(f"MarlVecEnv: env_method('{method_name}') is not supported")

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        return [False] * self.num_envs
