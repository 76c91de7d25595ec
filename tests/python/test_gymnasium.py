"""partsim's environments inside Gymnasium: the ids that `import partsim` registers,
Gymnasium's own environment checker on every id and observation mode, gymnasium.make and
make_vec (with the truncation of make's TimeLimit wrapper and of the environment agreeing),
Gymnasium's wrappers and its SyncVectorEnv over made environments, held against
VectorOpenCabinetEnv.
"""

import inspect
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import AutoresetMode

import partsim
import partsim.envs as envs

IDS = {"partsim/OpenCabinetDrawer-v0": "drawer", "partsim/OpenCabinetDoor-v0": "door"}
SMALL = (32, 24)  # camera width, height
SEED = 5


def default_max_episode_steps():
    return inspect.signature(envs.OpenCabinetEnv).parameters["max_episode_steps"].default


def test_import_registers_the_ids_once():
    for env_id, task in IDS.items():
        spec = gymnasium.spec(env_id)
        assert spec.entry_point == "partsim.envs:OpenCabinetEnv"
        assert spec.vector_entry_point == "partsim.envs:VectorOpenCabinetEnv"
        assert spec.kwargs == {"task": task}
        assert spec.max_episode_steps == default_max_episode_steps() == 250
    # registering again (a second import) keeps the specs and warns nothing
    before = {i: gymnasium.registry[i] for i in IDS}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        partsim._register_gymnasium_envs()
    assert all(gymnasium.registry[i] is before[i] for i in IDS)


@pytest.mark.parametrize("obs_mode", envs.OBS_MODES)
@pytest.mark.parametrize("env_id", IDS)
def test_check_env_passes_on_every_id_and_mode(env_id, obs_mode):
    made = gymnasium.make(env_id, obs_mode=obs_mode, camera_size=SMALL)
    env = made.unwrapped
    assert isinstance(env, envs.OpenCabinetEnv) and env.task_type == partsim.parse_task_type(
        IDS[env_id])
    assert env.obs_mode == obs_mode and env.spec.id == env_id
    assert made.spec.max_episode_steps == 250  # make's TimeLimit
    # the checker also makes the id with render_mode="rgb_array" and renders
    check_env(env)
    check_env(made)
    made.close()
    with pytest.raises(RuntimeError, match="closed"):
        env.reset(seed=0)


def test_made_env_renders_and_closes_with_with():
    with gymnasium.make("partsim/OpenCabinetDoor-v0", render_mode="rgb_array",
                        camera_size=SMALL) as env:
        env.reset(seed=SEED)
        frame = env.render()
        assert frame.shape == (SMALL[1], SMALL[0], 3) and frame.dtype == np.uint8
    with pytest.raises(RuntimeError, match="closed"):
        env.unwrapped.step(np.zeros(7))


def test_truncation_of_make_follows_its_time_limit():
    zero = np.zeros(7, dtype=np.float32)
    # shorter than the environment's own default
    env = gymnasium.make("partsim/OpenCabinetDrawer-v0", max_episode_steps=3)
    env.reset(seed=SEED)
    truncs = [env.step(zero)[3] for _ in range(3)]
    assert truncs == [False, False, True]
    env.close()
    # longer: the environment's own limit (250 when made directly) does not cut it short
    n = default_max_episode_steps() + 5
    env = gymnasium.make("partsim/OpenCabinetDrawer-v0", max_episode_steps=n)
    env.reset(seed=SEED)
    truncs = []
    for _ in range(n):
        _, _, terminated, truncated, _ = env.step(zero)
        assert not terminated
        truncs.append(truncated)
    assert truncs.index(True) == n - 1
    env.close()


def test_make_vec_with_the_vector_entry_point():
    vec = gymnasium.make_vec("partsim/OpenCabinetDoor-v0", num_envs=2,
                             vectorization_mode="vector_entry_point")
    assert isinstance(vec, envs.VectorOpenCabinetEnv) and vec.num_envs == 2
    assert vec.metadata["autoreset_mode"] is AutoresetMode.NEXT_STEP
    assert all(e.max_episode_steps == 250 and e.task_type == partsim.TaskType.OPEN_DOOR
               for e in vec.envs)
    vec.close()
    # the default vectorization mode of an id with a vector entry point; kwargs pass through
    vec = gymnasium.make_vec("partsim/OpenCabinetDrawer-v0", num_envs=2, max_episode_steps=2,
                             autoreset_mode="SameStep", obs_mode="raw")
    assert isinstance(vec, envs.VectorOpenCabinetEnv)
    assert vec.metadata["autoreset_mode"] is AutoresetMode.SAME_STEP
    vec.reset(seed=SEED)
    vec.step(np.zeros((2, 7)))
    obs, _, _, truncs, infos = vec.step(np.zeros((2, 7)))
    assert obs.shape == (2, 46) and truncs.all() and infos["_final_obs"].all()
    vec.close()


def test_sync_vector_env_of_made_envs_equals_vector_open_cabinet_env():
    """Gymnasium's SyncVectorEnv (through make_vec's sync mode, and built by hand over make)
    gives what VectorOpenCabinetEnv gives, next-step autoreset included."""
    n, steps = 2, 3
    ours = gymnasium.make_vec("partsim/OpenCabinetDrawer-v0", num_envs=n,
                              vectorization_mode="vector_entry_point", max_episode_steps=steps)
    sync = gymnasium.make_vec("partsim/OpenCabinetDrawer-v0", num_envs=n,
                              vectorization_mode="sync", max_episode_steps=steps)
    by_hand = gymnasium.vector.SyncVectorEnv(
        [lambda: gymnasium.make("partsim/OpenCabinetDrawer-v0", max_episode_steps=steps)
         for _ in range(n)])
    assert isinstance(sync, gymnasium.vector.SyncVectorEnv)
    actions = np.random.default_rng(0).uniform(-1, 1, (steps + 2, n, 7)).astype(np.float32)
    runs = []
    for vec in (ours, sync, by_hand):
        assert vec.single_observation_space == ours.single_observation_space
        obs, infos = vec.reset(seed=SEED)
        run = [obs]
        for a in actions:
            obs, rewards, terms, truncs, infos = vec.step(a)
            run += [obs, rewards, terms, truncs, infos["progress"]]
        runs.append(run)
        vec.close()
    truncs = runs[0][1 + 5 * (steps - 1) + 3]  # of the step `steps`
    assert truncs.all() and not runs[0][1 + 5 * steps + 3].any()
    for run in runs[1:]:
        assert all(np.array_equal(a, b) for a, b in zip(runs[0], run))


def test_wrappers_apply():
    # episode statistics of a made environment
    env = gymnasium.wrappers.RecordEpisodeStatistics(
        gymnasium.make("partsim/OpenCabinetDrawer-v0", max_episode_steps=3))
    env.reset(seed=SEED)
    total = 0.0
    for _ in range(3):
        _, reward, _, truncated, info = env.step(np.zeros(7, dtype=np.float32))
        total += reward
    assert truncated and info["episode"]["l"] == 3
    assert np.isclose(info["episode"]["r"], total)
    env.close()
    # a visual observation flattened to one vector
    env = gymnasium.wrappers.FlattenObservation(
        gymnasium.make("partsim/OpenCabinetDrawer-v0", obs_mode="visual", camera_size=SMALL))
    w, h = SMALL
    assert env.observation_space.shape == (h * w * 3 + h * w + h * w + 14,)
    obs, _ = env.reset(seed=SEED)
    assert obs.shape == env.observation_space.shape and obs in env.observation_space
    # the flattened state is the state of the dict observation (keys in the space's order)
    state = env.unwrapped._observation()["state"]
    assert np.array_equal(obs[-14:], state)
    env.close()
    # vector statistics and action rescaling on VectorOpenCabinetEnv
    vec = gymnasium.wrappers.vector.RecordEpisodeStatistics(
        gymnasium.make_vec("partsim/OpenCabinetDoor-v0", num_envs=2, max_episode_steps=2))
    vec = gymnasium.wrappers.vector.RescaleAction(
        vec, min_action=np.float32(0.0), max_action=np.float32(2.0))
    vec.reset(seed=SEED)
    for _ in range(2):
        _, _, _, truncs, infos = vec.step(np.ones((2, 7), dtype=np.float32))  # action 0
    assert truncs.all() and infos["_episode"].all() and list(infos["episode"]["l"]) == [2, 2]
    vec.close()
