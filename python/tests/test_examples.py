"""The examples where users plug mjcf-forge in: a Gymnasium environment (a new compiled
variant per reset), robosuite's model-building step as one Scene call, and a Ray batch
that equals one process byte for byte."""
from __future__ import annotations

import mujoco
import numpy as np
import pytest

import bounds
from helpers import ROOT
from mjcf_forge import Scene

DEMO = ROOT / "corpora" / "scenes" / "demo" / "demo.toml"
PATCH_SCENE = ROOT / "corpora" / "scenes" / "patch" / "patch.toml"


# ---------------------------------------------------------------- Gymnasium

# The checker's advice on unbounded observations and unnormalized actions does not apply:
# positions are unbounded, and the actions are the robot's own control ranges.
@pytest.mark.filterwarnings("ignore:.*Box (observation|action) space:UserWarning")
def test_gym_env_passes_gymnasiums_checker():
    from gymnasium.utils.env_checker import check_env

    import gym_env

    # check_env resets with seeds and compares (observations must be reproducible).
    check_env(gym_env.SceneEnv(DEMO, max_episode_steps=5), skip_render_check=True)


def test_gym_env_draws_a_new_variant_per_reset_and_the_same_for_the_same_seed():
    import gym_env

    env = gym_env.SceneEnv(DEMO, max_episode_steps=3)
    obs, info = env.reset(seed=42)
    first_xml, first_variant = env.variant.xml, info["variant"]
    assert env.observation_space.contains(obs)
    # The same seed: the same scene, the same first observation.
    obs2, info2 = env.reset(seed=42)
    assert info2["variant"] == first_variant and env.variant.xml == first_xml
    np.testing.assert_array_equal(obs, obs2)
    # Unseeded resets: a new scene each episode (the demo randomizes a geom's orientation,
    # which is structure: each is compiled anew).
    seen = {first_variant}
    models = set()
    for _ in range(5):
        obs, info = env.reset()
        assert info["variant"] not in seen
        seen.add(info["variant"])
        models.add(id(env.model))
        assert isinstance(env.model, mujoco.MjModel)
        # The compiled model holds exactly the objects the variant placed.
        for body in info["objects"]:
            assert env.model.body(body).id > 0
        # Steps run the physics: the robot's state changes under a non-zero action.
        before = env.data.qpos.copy()
        truncated = False
        steps = 0
        while not truncated:
            obs, reward, terminated, truncated, info = env.step(env.action_space.high)
            assert env.observation_space.contains(obs) and np.isfinite(reward) and not terminated
            steps += 1
        assert steps == 3
        assert not np.array_equal(before, env.data.qpos)
    assert len(models) == 5
    # A variant by index (to replay a manifest line).
    _, info = env.reset(options={"variant": 7})
    assert info["variant"] == 7 and env.variant.xml == env.scene.variant(7).xml


# ---------------------------------------------------------------- robosuite users

def test_robosuite_lift_env_builds_each_episode_with_one_scene_call():
    import robosuite_lift

    env = robosuite_lift.Lift5Env(seed=3)
    info = env.reset()
    assert len(env.object_body_ids) == 5 and all(b > 0 for b in env.object_body_ids.values())
    assert len(env.robot_joints) == 7
    again = robosuite_lift.Lift5Env(seed=3)
    assert again.reset()["variant"] == info["variant"] and again.variant.xml == env.variant.xml
    assert env.reset()["variant"] != info["variant"]


def test_robosuite_lift_with_models_puts_each_object_on_the_table(tmp_path):
    import robosuite_lift

    xml, parts = robosuite_lift.build_lift_with_models()
    path = tmp_path / "lift.xml"
    path.write_text(xml)
    m = mujoco.MjModel.from_xml_path(str(path))
    assert set(parts["robot"].joints) <= {m.joint(i).name for i in range(m.njnt)}
    assert m.body_parentid[m.body(parts["gripper"].root_body).id] == m.body("robot0_right_hand").id
    table_top = m.site("table_top").pos[2] + m.body("table").pos[2]
    # MuJoCo's own geometry: each object's lowest point is on the table top (the model
    # tier's bottom_offset put it there).
    for name in ["can", "milk", "bread", "cereal", "lemon"]:
        # robosuite's object roots are unnamed: climb from a named body of the object.
        top = m.body(parts[name].bodies[0]).id
        while m.body_parentid[top] != 0:
            top = m.body_parentid[top]
        low = bounds.measure(str(path), [f"#{top}"], False)["results"][0]["min"][2]
        # MuJoCo keeps mesh vertices in float32: agreement to about 1e-9 m, not 1e-15.
        assert m.body_pos[top][2] + low == pytest.approx(table_top, abs=1e-7), name


# ---------------------------------------------------------------- Ray

def test_ray_shards_equal_one_process_byte_for_byte():
    import ray

    import ray_batch

    assert ray_batch.shard_bounds(10, 3) == [(0, 4), (4, 7), (7, 10)]
    ray_batch.start_local_ray(num_cpus=2)
    try:
        result = ray_batch.run_batch(Scene.load(DEMO), 300, 4)
        # Another split of the same range: the same bytes again.
        again = ray_batch.run_batch(Scene.load(DEMO), 300, 7)
    finally:
        ray.shutdown()
    assert result["identical"] and result["members"] == 600
    assert again["identical"] and again["sha256"] == result["sha256"]


def test_gym_env_patches_the_model_in_place_when_the_structure_repeats():
    import gym_env
    import judge

    env = gym_env.SceneEnv(PATCH_SCENE, max_episode_steps=2)
    env.reset(seed=1)
    for _ in range(12):
        patches = env.cache.patches
        env.reset()
        if env.cache.patches > patches:
            # A cached model patched in place: the one MuJoCo compiles from the XML.
            ref = mujoco.MjModel.from_xml_string(env.variant.xml)
            assert judge.compare_models(ref, env.model) == []
        env.step(env.action_space.sample())
    # Four structures: at most four compiles in thirteen resets, the rest patches.
    assert env.cache.compiles <= 4
    assert env.cache.patches == 13 - env.cache.compiles
