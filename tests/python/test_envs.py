"""Behaviour of partsim.envs: reset/step signatures and return types, observations inside
observation_space (Gymnasium's spaces), seeding and determinism, termination and truncation,
render and close, bad actions, clipping, the objects (targets checked when the environment is
made, the pool that objects=None draws from), and the vector environment (batched spaces, the
three autoreset modes, partial resets, the same results as the single environments).
Gymnasium's own checks, registration, make and wrappers: test_gymnasium.py.

Environments are slow to build (the cabinet is generated and compiled), so a few module-scoped
ones are shared; every test starts by resetting the environment it uses with a seed. Unless a
test says otherwise, an environment has one cabinet: the first generated one with a target.
"""

import inspect

import gymnasium
import numpy as np
import pytest
from gymnasium import spaces
from gymnasium.vector import AutoresetMode

import partsim
import partsim.envs as envs

SMALL = (32, 24)  # camera width, height
SEED = 7


def first_object(task="drawer"):
    """The first generated StorageFurniture index with a target for the task."""
    return partsim.find_task_objects(partsim.parse_task_type(task), 1, 0)[0]


def make(**kwargs):
    kw = dict(task="drawer", obs_mode="mobility", max_episode_steps=4, camera_size=SMALL)
    kw.update(kwargs)
    kw.setdefault("objects", first_object(kw["task"]))
    return envs.OpenCabinetEnv(**kw)


def make_vec(num_envs, **kwargs):
    kwargs.setdefault("objects", first_object(kwargs.get("task", "drawer")))
    return envs.VectorOpenCabinetEnv(num_envs, **kwargs)


def flat(obs):
    """An observation (array or dict of arrays) as one float64 vector."""
    if isinstance(obs, dict):
        return np.concatenate([np.asarray(obs[k], dtype=np.float64).ravel() for k in sorted(obs)])
    return np.asarray(obs, dtype=np.float64).ravel()


def rollout(env, seed, actions):
    """reset(seed) then the actions; everything returned, flattened to one vector."""
    obs, _ = env.reset(seed=seed)
    parts = [flat(obs)]
    for a in actions:
        obs, reward, terminated, truncated, _ = env.step(a)
        parts += [flat(obs), [reward, terminated, truncated]]
    return np.concatenate(parts)


def random_actions(n, seed=0):
    return np.random.default_rng(seed).uniform(-1, 1, (n, 7)).astype(np.float32)


@pytest.fixture(scope="module")
def env():
    """Drawer, mobility observations, gripper drawn in front of the cabinet, 4 steps."""
    e = make(init_on_handle=False)
    yield e
    e.close()


@pytest.fixture(scope="module")
def twin():
    """A second environment like `env`, for comparisons from the same state."""
    e = make(init_on_handle=False)
    yield e
    e.close()


@pytest.fixture(
    scope="module",
    params=[("drawer", "raw"), ("drawer", "mobility"), ("drawer", "visual"), ("door", "mobility")],
    ids=lambda p: f"{p[0]}-{p[1]}",
)
def mode_env(request):
    task, obs_mode = request.param
    e = make(task=task, obs_mode=obs_mode, init_on_handle=False)
    yield e
    e.close()


def check_obs(space, obs):
    assert space.contains(obs), (space, obs)
    assert obs in space
    if isinstance(obs, dict):
        for k, v in obs.items():
            assert isinstance(v, np.ndarray) and v.dtype == space[k].dtype, k
    else:
        assert isinstance(obs, np.ndarray) and obs.dtype == space.dtype


# --- the Env API ---------------------------------------------------------------------------


def test_class_attributes_and_spaces():
    assert issubclass(envs.OpenCabinetEnv, gymnasium.Env)
    assert issubclass(envs.VectorOpenCabinetEnv, gymnasium.vector.VectorEnv)
    assert not hasattr(envs, "Box") and not hasattr(envs, "Dict")  # Gymnasium's are used
    assert "rgb_array" in envs.OpenCabinetEnv.metadata["render_modes"]
    assert envs.OpenCabinetEnv.metadata["render_fps"] > 0
    sig = inspect.signature(envs.OpenCabinetEnv.reset)
    for name in ("seed", "options"):
        assert sig.parameters[name].kind is inspect.Parameter.KEYWORD_ONLY
        assert sig.parameters[name].default is None


def test_spaces_of_the_modes(mode_env):
    e = mode_env
    assert type(e.observation_space) is (spaces.Dict if e.obs_mode == "visual" else spaces.Box)
    assert e.action_space == spaces.Box(-1.0, 1.0, (7,), np.float32)
    if e.obs_mode == "raw":
        assert e.observation_space.shape == (46,)
    elif e.obs_mode == "mobility":
        assert e.observation_space.shape == (25,)
    else:
        sp = e.observation_space
        assert set(sp.keys()) == {"rgb", "depth", "mask", "state"}
        w, h = SMALL
        assert sp["rgb"].shape == (h, w, 3) and sp["rgb"].dtype == np.uint8
        assert sp["depth"].shape == (h, w) and sp["depth"].dtype == np.float32
        assert sp["mask"].shape == (h, w) and sp["mask"].dtype == np.uint8
        assert sp["state"].shape == (14,)


def test_reset_and_step_return_types_and_observations_in_space(mode_env):
    e = mode_env
    out = e.reset(seed=SEED)
    assert isinstance(out, tuple) and len(out) == 2
    obs, info = out
    assert isinstance(info, dict)
    check_obs(e.observation_space, obs)
    e.action_space.seed(0)
    first = None
    for i in range(3):
        out = e.step(e.action_space.sample())
        assert isinstance(out, tuple) and len(out) == 5
        obs, reward, terminated, truncated, info = out
        assert type(reward) is float and np.isfinite(reward)
        assert type(terminated) is bool and type(truncated) is bool
        assert isinstance(info, dict) and type(info["success"]) is bool
        check_obs(e.observation_space, obs)
        if first is None:
            first = (obs, flat(obs).copy())
    # returned observations are the caller's: later steps do not change them
    assert np.array_equal(flat(first[0]), first[1])
    obs, info = e.reset()  # no seed: continues the generator
    check_obs(e.observation_space, obs)
    obs, info = e.reset(seed=SEED + 1, options={})
    check_obs(e.observation_space, obs)


def test_visual_mask_marks_the_target():
    e = make(obs_mode="visual", init_on_handle=False)
    obs, _ = e.reset(seed=SEED)
    assert set(np.unique(obs["mask"])) <= {0, 1}
    assert obs["mask"].sum() > 0  # the front camera sees the target part
    assert obs["depth"].max() > 0
    e.close()


def test_same_seed_same_trajectory_and_different_seeds_differ(env, twin):
    actions = random_actions(4)
    a = rollout(env, SEED, actions)
    b = rollout(env, SEED, actions)  # the same env, after an episode
    c = rollout(twin, SEED, actions)  # another environment
    assert np.array_equal(a, b)
    assert np.array_equal(a, c)
    d = rollout(env, SEED + 1, actions)
    assert not np.array_equal(a, d)
    # reset() without a seed continues the seeded generator, the same way in both
    env.reset(seed=3)
    twin.reset(seed=3)
    assert np.array_equal(flat(env.reset()[0]), flat(twin.reset()[0]))


def test_seeding_seeds_the_action_space(env):
    env.reset(seed=11)
    x = env.action_space.sample()
    env.reset(seed=11)
    assert np.array_equal(x, env.action_space.sample())
    assert isinstance(env.np_random, np.random.Generator)
    assert env.unwrapped is env


def test_truncated_after_max_episode_steps(env):
    env.reset(seed=SEED)
    zero = np.zeros(7, dtype=np.float32)
    for i in range(env.max_episode_steps):
        obs, reward, terminated, truncated, info = env.step(zero)
        assert not terminated
        assert truncated == (i == env.max_episode_steps - 1)
        assert not info["success"]


def test_terminated_on_success():
    e = make(init_on_handle=True, max_episode_steps=80)
    obs, info = e.reset(seed=SEED)
    assert info["touching"] and not info["success"]
    lo, hi = e.task.target_joint.get_limits()
    opening = 1.0 if abs(lo) <= abs(hi) else -1.0  # opens towards the far limit
    action = np.zeros(7, dtype=np.float32)
    action[:3] = 0.5 * opening * obs[3:6]  # mobility obs: the joint axis direction
    action[6] = -1.0  # keep the gripper closed on the handle
    for i in range(e.max_episode_steps):
        obs, reward, terminated, truncated, info = e.step(action)
        if terminated or truncated:
            break
    assert terminated and not truncated, info
    assert info["success"] and info["progress"] >= 0.9
    assert reward >= 1.0  # the success bonus
    e.close()


def test_without_the_gripper_action_the_fingers_keep_the_handle():
    # the same episode twice: the 6-value twist, and the 7-value action with the fingers told
    # to open; only the second lets go of the handle
    held = make(init_on_handle=True, gripper_action=False, max_episode_steps=20)
    free = make(init_on_handle=True, max_episode_steps=20)
    assert held.action_space.shape == (6,) and free.action_space.shape == (7,)
    held.reset(seed=SEED)
    free.reset(seed=SEED)
    twist = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0], dtype=np.float32)
    for _ in range(10):
        _, _, _, _, h = held.step(twist)
        _, _, _, _, f = free.step(np.append(twist, 1.0).astype(np.float32))
    assert h["touching"] and not f["touching"]
    assert held.task.get_gripper_opening() < 0.5 < free.task.get_gripper_opening()
    with pytest.raises(ValueError, match=r"shape \(6,\)"):
        held.step(np.zeros(7, dtype=np.float32))
    held.close()
    free.close()

    vec = make_vec(2, gripper_action=False)
    assert vec.single_action_space.shape == (6,) and vec.action_space.shape == (2, 6)
    vec.reset(seed=0)
    _, _, _, _, infos = vec.step(np.zeros((2, 6)))
    assert infos["touching"].all()
    with pytest.raises(ValueError, match=r"\(2, 6\)"):
        vec.step(np.zeros((2, 7)))
    vec.close()


def test_reset_options():
    e = make(init_on_handle=False)
    with pytest.raises(ValueError):
        e.reset(seed=0, options={"colour": "red"})
    with pytest.raises(ValueError):
        e.reset(seed=0, options={"object": 5})
    names = e.reset(seed=0)[1]["target"], e.reset(seed=1)[1]["target"]
    candidates = None
    for t in range(3):
        _, info = e.reset(seed=0, options={"target": t})
        candidates = e.task.get_target_candidates()
        assert info["target"] == candidates[t]
    with pytest.raises(ValueError):
        e.reset(seed=0, options={"target": len(candidates)})
    # an option holds for its episode only: the seed draws the target again afterwards
    assert (e.reset(seed=0)[1]["target"], e.reset(seed=1)[1]["target"]) == names
    e.close()


def test_render():
    e = make(render_mode="rgb_array", init_on_handle=False)
    with pytest.raises(RuntimeError):
        e.render()  # before reset
    e.reset(seed=SEED)
    frame = e.render()
    w, h = SMALL
    assert isinstance(frame, np.ndarray) and frame.shape == (h, w, 3) and frame.dtype == np.uint8
    assert frame.max() > 0
    e.step(np.ones(7, dtype=np.float32))
    assert e.render().shape == (h, w, 3)
    e.close()
    # in visual mode render() shows the state of the last observation
    v = make(obs_mode="visual", render_mode="rgb_array", init_on_handle=False)
    obs, _ = v.reset(seed=SEED)
    assert np.array_equal(v.render(), obs["rgb"])
    obs, *_ = v.step(np.ones(7, dtype=np.float32))
    assert np.array_equal(v.render(), obs["rgb"])
    obs, _ = v.reset(seed=SEED + 1)
    assert np.array_equal(v.render(), obs["rgb"])
    v.close()


def test_render_mode_none_and_bad_arguments(env):
    env.reset(seed=SEED)
    # None, with a warning that says how to get frames
    with pytest.warns(UserWarning, match='render_mode="rgb_array"'):
        assert env.render_mode is None and env.render() is None
    with pytest.raises(ValueError):
        make(render_mode="human")
    with pytest.raises(ValueError):
        make(obs_mode="pixels")
    with pytest.raises(ValueError):
        make(max_episode_steps=0)


def test_close():
    e = make(init_on_handle=False)
    e.reset(seed=SEED)
    e.step(np.zeros(7))
    e.close()
    e.close()  # closing twice is allowed
    with pytest.raises(RuntimeError):
        e.step(np.zeros(7))
    with pytest.raises(RuntimeError):
        e.reset(seed=SEED)
    with envs.OpenCabinetEnv(max_episode_steps=2, init_on_handle=False) as ctx:
        ctx.reset(seed=0)
    with pytest.raises(RuntimeError):
        ctx.reset(seed=0)


def test_step_before_reset():
    e = make(init_on_handle=False)
    with pytest.raises(RuntimeError):
        e.step(np.zeros(7))
    e.close()


# --- bad actions and clipping -----------------------------------------------------------


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros(6),
        np.zeros(8),
        np.zeros((1, 7)),
        np.zeros((7, 1)),
        0.0,
        [],
        [0, 0, 0, np.nan, 0, 0, 0],
        [0, 0, 0, 0, 0, 0, np.inf],
        [-np.inf, 0, 0, 0, 0, 0, 0],
        np.full(7, np.nan, dtype=np.float32),
        ["a", 0, 0, 0, 0, 0, 0],
    ],
    ids=["6", "8", "1x7", "7x1", "scalar", "empty", "nan", "inf", "-inf", "nan32", "str"],
)
def test_bad_actions_raise_and_change_nothing(env, twin, bad):
    good = np.array([0.8, -0.3, 0.2, 0.1, 0.0, -0.2, -1.0], dtype=np.float32)
    env.reset(seed=SEED)
    twin.reset(seed=SEED)
    env.step(good)
    twin.step(good)
    before = env.task.get_raw_observation().copy()
    with pytest.raises(ValueError):
        env.step(bad)
    assert np.array_equal(env.task.get_raw_observation(), before)
    assert env.task.get_elapsed() == twin.task.get_elapsed()
    # the next step goes on as if the bad call had not happened
    a = env.step(good)
    b = twin.step(good)
    assert np.array_equal(a[0], b[0]) and a[1:4] == b[1:4]


def test_out_of_range_actions_are_clipped(env, twin):
    big = np.array([5.0, -5.0, 0.3, 2.0, -3.0, 0.0, 7.0])
    clipped = np.clip(big, -1.0, 1.0)
    env.reset(seed=SEED)
    twin.reset(seed=SEED)
    for _ in range(2):
        a = env.step(big)
        b = twin.step(clipped)
        assert np.array_equal(a[0], b[0]) and a[1:4] == b[1:4]
    # float32, float64 and lists are the same action
    env.reset(seed=SEED)
    twin.reset(seed=SEED)
    a = env.step([0.5, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0])
    b = twin.step(np.array([0.5, 0, 0, 0, 0, 0, -1], dtype=np.float32))
    assert np.array_equal(a[0], b[0])


# --- the vector environment ----------------------------------------------------------------


def test_vector_env_spaces_shapes_autoreset_and_determinism():
    n, steps = 2, 3
    vec = make_vec(
        n, obs_mode="mobility", max_episode_steps=steps, init_on_handle=False
    )
    assert vec.num_envs == n
    assert vec.single_action_space == spaces.Box(-1, 1, (7,), np.float32)
    assert vec.action_space.shape == (n, 7)
    assert vec.single_observation_space.shape == (25,)
    assert vec.observation_space.shape == (n, 25)
    assert "rgb_array" in vec.metadata["render_modes"]

    obs, infos = vec.reset(seed=SEED)
    assert vec.observation_space.contains(obs)
    assert infos["progress"].shape == (n,) and infos["_progress"].all()
    actions = random_actions(steps + 2, seed=1)
    batched = [np.stack([a, -a]) for a in actions]  # env i gets action (-1)^i a
    vec_traj = [obs]
    for k in range(steps + 2):
        obs, rewards, terms, truncs, infos = vec.step(batched[k])
        assert obs.shape == (n, 25) and vec.observation_space.contains(obs)
        assert rewards.shape == (n,) and rewards.dtype == np.float64
        assert terms.shape == (n,) and terms.dtype == bool
        assert truncs.shape == (n,) and truncs.dtype == bool
        assert isinstance(infos, dict) and infos["success"].shape == (n,)
        if k == steps - 1:
            assert truncs.all() and not terms.any()
        if k == steps:  # next-step autoreset: a new episode's first observation
            assert not truncs.any() and not terms.any() and np.all(rewards == 0.0)
            assert np.all(infos["elapsed"] == 0.0)
        vec_traj.append(obs)
        vec_traj.append(rewards)
    # the same as each environment run alone, with the same seeds
    for i in range(n):
        single = make(obs_mode="mobility", max_episode_steps=steps, init_on_handle=False)
        obs, _ = single.reset(seed=SEED + i)
        ref = [obs]
        for k in range(steps + 2):
            if k == steps:
                obs, _ = single.reset()
                reward = 0.0
            else:
                obs, reward, *_ = single.step(batched[k][i])
            ref.append(obs)
            ref.append(reward)
        single.close()
        got = [x[i] for x in vec_traj]
        assert all(np.array_equal(g, r) for g, r in zip(got, ref)), f"env {i}"

    # bad input
    with pytest.raises(ValueError):
        vec.step(np.zeros((n + 1, 7)))
    with pytest.raises(ValueError):
        vec.step(np.full((n, 7), np.nan))
    with pytest.raises(ValueError):
        vec.reset(seed=[1, 2, 3])
    seeded = vec.reset(seed=[SEED, SEED + 1])[0]
    assert np.array_equal(seeded, vec.reset(seed=SEED)[0])
    vec.close()
    vec.close()
    with pytest.raises(RuntimeError):
        vec.step(np.zeros((n, 7)))


def test_vector_env_visual_observations():
    # rendered on two threads: every sub-environment keeps to its thread, since a scene's GL
    # context stays current on the thread that last rendered with it
    n, steps = 2, 2
    vec = make_vec(
        n, obs_mode="visual", max_episode_steps=steps, camera_size=SMALL, init_on_handle=False
    )
    w, h = SMALL
    obs, _ = vec.reset(seed=SEED)
    assert obs["rgb"].shape == (n, h, w, 3) and obs["rgb"].dtype == np.uint8
    assert obs["depth"].shape == (n, h, w) and obs["mask"].shape == (n, h, w)
    assert vec.observation_space.contains(obs)
    traj = [obs]
    for k in range(2 * steps + 2):  # through two autoresets
        obs, *_ = vec.step(np.full((n, 7), 0.5))
        assert vec.observation_space.contains(obs)
        traj.append(obs)
    vec.close()
    # the pictures are those of each environment alone
    single = make(obs_mode="visual", max_episode_steps=steps, init_on_handle=False)
    ref = [single.reset(seed=SEED + 1)[0]]
    for k in range(2 * steps + 2):
        done = k % (steps + 1) == steps
        ref.append(single.reset()[0] if done else single.step(np.full(7, 0.5))[0])
    single.close()
    for k, (got, want) in enumerate(zip(traj, ref)):
        assert all(np.array_equal(got[key][1], want[key]) for key in want), f"step {k}"


def test_vector_env_fewer_workers_than_envs():
    kw = dict(obs_mode="mobility", max_episode_steps=3, init_on_handle=False)
    a = make_vec(3, workers=1, **kw)
    b = make_vec(3, workers=2, **kw)
    xa, xb = a.reset(seed=SEED)[0], b.reset(seed=SEED)[0]
    assert np.array_equal(xa, xb)
    for act in random_actions(4, seed=2):
        batch = np.stack([act, 0.5 * act, -act])
        ra, rb = a.step(batch), b.step(batch)
        assert np.array_equal(ra[0], rb[0]) and np.array_equal(ra[1], rb[1])
    a.close()
    b.close()


def test_env_on_a_partnet_mobility_folder(tmp_path):
    """objects may name PartNet-Mobility folders: the generator's first drawer cabinet, written
    as one by a task, gives the same targets as its index."""
    import partsim

    index = partsim.find_task_objects(partsim.TaskType.PULL_DRAWER, 1, 0)[0]
    o = partsim.TaskOptions()
    o.object_index, o.asset_dir, o.cameras = index, str(tmp_path), False
    partsim.ArticulationTask(o)
    folder = next(p.parent for p in tmp_path.rglob("mobility.urdf"))
    by_folder = make(objects=[folder])
    by_index = make(objects=index)
    try:
        obs, info = by_folder.reset(seed=SEED)
        _, info_index = by_index.reset(seed=SEED)
        assert info["object"] == folder.name
        assert info["target"] == info_index["target"]
        obs, reward, terminated, truncated, info = by_folder.step(np.zeros(7, np.float32))
        assert by_folder.observation_space.contains(obs.astype(np.float32))
    finally:
        by_folder.close()
        by_index.close()
    with pytest.raises(ValueError, match="not a PartNet-Mobility folder"):
        make(objects=[str(tmp_path / "nothing")])


def test_vector_env_render():
    n = 2
    vec = make_vec(
        n, render_mode="rgb_array", camera_size=SMALL, init_on_handle=False, workers=2
    )
    assert vec.render_mode == "rgb_array"
    with pytest.raises(RuntimeError):
        vec.render()  # before reset
    vec.reset(seed=SEED)
    frames = vec.render()
    w, h = SMALL
    assert isinstance(frames, tuple) and len(frames) == n
    for i, f in enumerate(frames):
        assert f.shape == (h, w, 3) and f.dtype == np.uint8 and f.max() > 0
        # the frame of sub-environment i is what that environment renders itself
        assert np.array_equal(f, vec.envs[i].render())
    vec.close()
    plain = make_vec(1, init_on_handle=False)
    plain.reset(seed=SEED)
    with pytest.warns(UserWarning, match="VectorOpenCabinetEnv"):
        assert plain.render() is None
    plain.close()


# --- autoreset modes and partial resets ---------------------------------------------------------


def single_run(seed, actions_and_resets):
    """Observations and infos of one environment (2-step episodes) reset with ``seed``, then
    given actions, or None for a reset without a seed: [(obs, info)] after each call."""
    e = make(max_episode_steps=2, init_on_handle=False)
    out = [e.reset(seed=seed)]
    for a in actions_and_resets:
        if a is None:
            out.append(e.reset())
        else:
            obs, _, _, _, info = e.step(a)
            out.append((obs, info))
    e.close()
    return out


def test_autoreset_mode_argument_and_metadata():
    for mode, want in [
        (None, AutoresetMode.NEXT_STEP),
        (AutoresetMode.SAME_STEP, AutoresetMode.SAME_STEP),
        ("SameStep", AutoresetMode.SAME_STEP),
        ("same_step", AutoresetMode.SAME_STEP),
        ("DISABLED", AutoresetMode.DISABLED),
        ("NextStep", AutoresetMode.NEXT_STEP),
    ]:
        kw = {} if mode is None else {"autoreset_mode": mode}
        vec = make_vec(1, init_on_handle=False, **kw)
        assert vec.autoreset_mode is want and vec.metadata["autoreset_mode"] is want
        vec.close()
    # per instance: the class and the single environment's metadata are not changed
    assert "autoreset_mode" not in envs.OpenCabinetEnv.metadata
    with pytest.raises(ValueError, match="autoreset_mode"):
        make_vec(1, autoreset_mode="sometimes")


def test_same_step_autoreset_returns_the_next_episode_and_the_final_observation():
    n, zero = 2, np.zeros(7)
    vec = make_vec(n, max_episode_steps=2, init_on_handle=False, autoreset_mode="SameStep")
    obs0, _ = vec.reset(seed=SEED)
    _, _, terms, truncs, infos = vec.step(np.zeros((n, 7)))
    assert not truncs.any() and "final_obs" not in infos
    obs, rewards, terms, truncs, infos = vec.step(np.zeros((n, 7)))
    assert truncs.all() and not terms.any()
    assert infos["_final_obs"].all() and infos["_final_info"].all()
    for i in range(n):
        ref = single_run(SEED + i, [zero, zero, None, zero])
        # the episode's last observation and info in final_*, the next episode's first returned
        assert np.array_equal(infos["final_obs"][i], ref[2][0])
        assert infos["final_info"]["elapsed"][i] == ref[2][1]["elapsed"] > 0
        assert np.array_equal(obs[i], ref[3][0])
        assert infos["elapsed"][i] == 0.0
    # the next step is a step of the new episode (no reset step as in next-step mode)
    obs, rewards, terms, truncs, infos = vec.step(np.zeros((n, 7)))
    assert "final_obs" not in infos and not truncs.any()
    for i in range(n):
        ref = single_run(SEED + i, [zero, zero, None, zero])
        assert np.array_equal(obs[i], ref[4][0])
        assert infos["elapsed"][i] == ref[4][1]["elapsed"] > 0
    vec.close()


def test_same_step_autoreset_with_cameras():
    # the copies' resets run on their own threads, where their OpenGL contexts live
    vec = make_vec(2, obs_mode="visual", camera_size=SMALL, max_episode_steps=1,
                   init_on_handle=False, autoreset_mode=AutoresetMode.SAME_STEP)
    first, _ = vec.reset(seed=SEED)
    obs, _, _, truncs, infos = vec.step(np.zeros((2, 7)))
    assert truncs.all() and infos["_final_obs"].all()
    assert set(infos["final_obs"][0]) == {"rgb", "depth", "mask", "state"}
    assert vec.observation_space.contains(obs)
    # the new episodes were drawn by the generators after their first: not the seeded start
    assert not np.array_equal(obs["state"], first["state"])
    vec.close()


def test_disabled_autoreset_needs_masked_resets():
    n, zero = 2, np.zeros(7)
    vec = make_vec(n, max_episode_steps=2, init_on_handle=False, autoreset_mode="Disabled")
    vec.reset(seed=SEED)
    vec.step(np.zeros((n, 7)))
    last, _, _, truncs, infos = vec.step(np.zeros((n, 7)))
    assert truncs.all() and "final_obs" not in infos
    with pytest.raises(RuntimeError, match=r"sub-environments \[0, 1\].*reset_mask"):
        vec.step(np.zeros((n, 7)))
    # reset only copy 0: copy 1 keeps its last observation and gives no info
    obs, infos = vec.reset(options={"reset_mask": np.array([True, False])})
    ref0 = single_run(SEED, [zero, zero, None])
    assert np.array_equal(obs[0], ref0[3][0]) and np.array_equal(obs[1], last[1])
    assert infos["_elapsed"].tolist() == [True, False] and infos["elapsed"][0] == 0.0
    with pytest.raises(RuntimeError, match=r"sub-environments \[1\]"):
        vec.step(np.zeros((n, 7)))
    vec.reset(options={"reset_mask": np.array([False, True])})
    obs, _, _, truncs, infos = vec.step(np.zeros((n, 7)))
    assert not truncs.any() and np.allclose(infos["elapsed"], 1 / 25)  # one step in
    for i in range(n):
        assert np.array_equal(obs[i], single_run(SEED + i, [zero, zero, None, zero])[4][0])
    # bad masks
    with pytest.raises(TypeError):
        vec.reset(options={"reset_mask": [True, False]})
    with pytest.raises(ValueError, match="shape"):
        vec.reset(options={"reset_mask": np.ones(3, dtype=bool)})
    with pytest.raises(ValueError, match="no sub-environment"):
        vec.reset(options={"reset_mask": np.zeros(n, dtype=bool)})
    vec.close()


def test_reset_mask_in_next_step_mode_and_before_a_full_reset():
    n = 2
    vec = make_vec(n, max_episode_steps=3, init_on_handle=False)
    with pytest.raises(RuntimeError, match="never reset"):
        vec.reset(options={"reset_mask": np.array([True, False])})
    a, _ = vec.reset(seed=SEED)
    b, _ = vec.reset(seed=[SEED + 5, SEED + 6], options={"reset_mask": np.array([False, True])})
    assert np.array_equal(b[0], a[0]) and not np.array_equal(b[1], a[1])
    assert np.array_equal(b[1], make(max_episode_steps=3, init_on_handle=False).reset(
        seed=SEED + 6)[0])
    vec.close()


# --- objects: targets checked when made, the pool of objects=None ------------------------------


def test_objects_without_a_target_are_refused_when_made(tmp_path):
    no_drawer = min(set(range(10)) - set(partsim.find_task_objects(
        partsim.TaskType.PULL_DRAWER, 10, 0)))
    no_door = min(set(range(10)) - set(partsim.find_task_objects(
        partsim.TaskType.OPEN_DOOR, 10, 0)))
    with pytest.raises(ValueError, match=rf"StorageFurniture object {no_drawer} .*'drawer'"):
        envs.OpenCabinetEnv(task="drawer", objects=[first_object("drawer"), no_drawer])
    with pytest.raises(ValueError, match=rf"StorageFurniture object {no_door} .*'door'"):
        envs.VectorOpenCabinetEnv(2, task="door", objects=no_door)
    with pytest.raises(ValueError, match="-3"):
        envs.OpenCabinetEnv(objects=-3)
    # a folder: the generator's first door-only cabinet, written by a door task
    o = partsim.TaskOptions()
    o.type, o.object_index, o.asset_dir, o.cameras = (
        partsim.TaskType.OPEN_DOOR, no_drawer, str(tmp_path), False)
    partsim.ArticulationTask(o)
    folder = next(p.parent for p in tmp_path.rglob("mobility.urdf"))
    with pytest.raises(ValueError, match=rf"{folder.name}.*'drawer'.*semantics.txt"):
        envs.OpenCabinetEnv(task="drawer", objects=[folder])
    door = envs.OpenCabinetEnv(task="door", objects=[folder], max_episode_steps=2)
    assert door.reset(seed=0)[1]["object"] == folder.name
    door.close()


def test_default_objects_are_a_pool_drawn_by_the_seed():
    e = envs.OpenCabinetEnv(task="door", max_episode_steps=2, init_on_handle=False)
    assert e.objects == partsim.find_task_objects(partsim.TaskType.OPEN_DOOR, 16, 0)
    seeds = range(6)
    drawn = [e.reset(seed=s)[1]["object"] for s in seeds]
    assert len(set(drawn)) > 1  # different seeds, different cabinets
    assert set(drawn) <= set(e.objects)
    # the same seed, the same cabinet and the same first observation
    obs, info = e.reset(seed=3)
    again, info_again = e.reset(seed=3)
    assert info["object"] == info_again["object"] == drawn[3]
    assert np.array_equal(obs, again)
    assert [e.reset(seed=s)[1]["object"] for s in seeds] == drawn
    assert len(e._tasks) == len(set(drawn))  # one task per cabinet drawn, built lazily
    e.close()
    one = envs.OpenCabinetEnv(pool_size=1, max_episode_steps=2)
    assert one.objects == [first_object("drawer")]
    one.close()
    with pytest.raises(ValueError, match="pool_size"):
        envs.OpenCabinetEnv(pool_size=0)
