"""What the robosuite comparisons build, written once against robosuite's API (imported by
the scripts beside it; robosuite is imported by the caller's venv, real or stubbed).

- :func:`part_class`: a ``MujocoXMLModel`` with only the abstract properties it needs
  (prefix ``idn + "_"``), over robosuite's classes or ``mjcf_forge.base``'s;
- :func:`lift5_builder`: the lift5 scene (``benches/scenes/lift5.toml``) the robosuite way:
  Panda with its mount and gripper, a table arena, 5 objects drawn from lift5's pool,
  coloured and placed by robosuite's sampler.
"""

from __future__ import annotations

N_OBJECTS = 5


def part_class(model_base, assets):
    """A ``model_base`` (robosuite's ``MujocoXMLModel``, or one standing for it) loaded
    from ``assets / rel``, its collision geoms coloured ``rgba``."""

    class Part(model_base):
        def __init__(self, rel, idn, rgba):
            self._rgba = rgba
            super().__init__(str(assets / rel), idn=idn)

        @property
        def contact_geom_rgba(self):
            return self._rgba

        @property
        def _important_sites(self):
            return {}

        @property
        def _important_geoms(self):
            return {}

        @property
        def _important_sensors(self):
            return {}

    return Part


def lift5_builder():
    """``build(seed, index) -> (xml, placements)``: variant ``index`` of lift5 the robosuite
    way (its own numpy generator seeded ``[seed, index]``; ``placements`` as robosuite's
    sampler returns them)."""
    import numpy as np
    from robosuite.models.arenas import TableArena
    from robosuite.models.bases import robot_base_factory
    from robosuite.models.grippers import gripper_factory
    from robosuite.models.objects import (
        BottleObject,
        BreadObject,
        CanObject,
        CerealObject,
        LemonObject,
        MilkObject,
    )
    from robosuite.models.robots import create_robot
    from robosuite.models.tasks import ManipulationTask
    from robosuite.utils.mjcf_utils import array_to_string
    from robosuite.utils.placement_samplers import UniformRandomSampler

    # lift5.toml's pool, in its order.
    pool = [CanObject, MilkObject, BreadObject, CerealObject, LemonObject, BottleObject]
    table_full_size = (0.8, 0.8, 0.05)
    table_offset = (0, 0, 0.8)

    def build(seed: int, index: int):
        rng = np.random.default_rng([seed, index])
        robot = create_robot("Panda", idn=0)
        robot.add_base(base=robot_base_factory(robot.default_base, idn=0))
        robot.update_joints()
        robot.update_actuators()
        gripper = gripper_factory(robot.default_gripper["right"], idn="0_right")
        robot.add_gripper(gripper, robot.eef_name["right"])
        robot.set_base_xpos(robot.base_xpos_offset["table"](table_full_size[0]))
        arena = TableArena(
            table_full_size=table_full_size,
            table_friction=(1.0, 5e-3, 1e-4),
            table_offset=table_offset,
        )
        arena.set_origin([0, 0, 0])
        choice = rng.integers(len(pool), size=N_OBJECTS)
        objects = [pool[c](name=f"object{i}") for i, c in enumerate(choice)]
        for obj in objects:
            for geom in obj.get_obj().iter("geom"):
                geom.set("rgba", array_to_string(np.append(rng.uniform(0.0, 1.0, 3), 1.0)))
        sampler = UniformRandomSampler(
            name="ObjectSampler",
            mujoco_objects=objects,
            x_range=[-0.3, 0.3],
            y_range=[-0.3, 0.3],
            rotation=None,
            rotation_axis="z",
            ensure_object_boundary_in_range=False,
            ensure_valid_placement=True,
            reference_pos=table_offset,
            z_offset=0.01,
            rng=rng,
        )
        placements = sampler.sample()
        for pos, quat, obj in placements.values():
            obj.get_obj().set("pos", array_to_string(pos))
            obj.get_obj().set("quat", array_to_string(quat))
        task = ManipulationTask(mujoco_arena=arena, mujoco_robots=[robot], mujoco_objects=objects)
        return task.get_xml(), placements

    return build
