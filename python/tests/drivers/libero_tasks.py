"""LIBERO's tasks as the drivers and scripts find them, without torch: the suites' task
map, a task's BDDL file and its init states. Import it after ``mjcf_forge.robosuite.use()``
where the switch is wanted (``libero.libero`` is imported here).

    from libero_tasks import bddl_file, init_states, task_map
"""
from __future__ import annotations

import importlib.util
import os
import pickle
import zipfile

from libero.libero import get_libero_path


def task_map() -> dict:
    """LIBERO's suites and their tasks in order (libero.libero.benchmark's own map; its
    package imports torch, so the module is loaded alone)."""
    path = os.path.join(os.path.dirname(get_libero_path("bddl_files")), "benchmark", "libero_suite_task_map.py")
    spec = importlib.util.spec_from_file_location("libero_suite_task_map", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.libero_task_map


def task_name(suite: str, index: int) -> str:
    """The name of task ``index`` of ``suite``."""
    return task_map()[suite][index]


def bddl_file(suite: str, name: str) -> str:
    """The BDDL file of task ``name`` of ``suite``."""
    return os.path.join(get_libero_path("bddl_files"), suite, name + ".bddl")


def init_states(suite: str, name: str):
    """The task's init states (a numpy array): LIBERO's ``torch.save`` zip, whose pickle
    holds one numpy array, read without torch."""
    path = os.path.join(get_libero_path("init_states"), suite, name + ".pruned_init")
    with zipfile.ZipFile(path) as z:
        data = next(n for n in z.namelist() if n.endswith("/data.pkl"))
        return pickle.loads(z.read(data))
