"""Sharing between Python threads: one Scene, one Document; and the GIL is released
during long calls (other Python threads keep running)."""
from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor

from helpers import RS_ASSETS
from mjcf_forge import Document, Scene

PANDA = RS_ASSETS / "robots" / "panda" / "robot.xml"


def test_threads_sharing_one_scene_get_what_one_thread_gets():
    scene = Scene.load()
    expected = [scene.variant(i).xml for i in range(64)]
    with ThreadPoolExecutor(8) as pool:
        got = list(pool.map(lambda i: scene.variant(i).xml, range(64)))
    assert got == expected
    # Several streams of one scene at once, each in order.
    def stream(start):
        return [v.xml for v in scene.variants(range(start, start + 16), threads=2)]

    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(stream, [0, 16, 32, 48]))
    assert sum(results, []) == expected


def test_threads_sharing_one_document_read_and_edit_safely():
    doc = Document.load(PANDA)
    bodies = [b.name for b in doc.find_all_named("body") if b.name]
    original = doc.to_xml()
    errors = []

    def work(k):
        try:
            for _ in range(30):
                text = doc.to_xml()
                assert text.startswith("<mujoco")
                el = doc.find_named("body", bodies[k])
                el.set("user", [k])  # each thread edits its own body
                assert doc.find_named("body", bodies[k])["user"] == str(k)
                doc.copy()
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    assert all(doc.find_named("body", bodies[k])["user"] == str(k) for k in range(8))
    assert doc.to_xml() != original


def test_threads_moving_elements_between_two_documents_in_both_directions_finish():
    # Copying between documents locks both; threads copying A->B and B->A at once must not
    # each hold one lock and wait for the other. Handles are shared between the threads.
    a, b = Document.load(PANDA), Document.load(PANDA)
    errors = []

    def work(k):
        try:
            src, dst = (a, b) if k % 2 else (b, a)
            for i in range(40):
                el = src.find(".//body[@name='link3']")
                dst.worldbody.append(el)  # copied in; the handle follows the copy
                assert el.parent is dst.worldbody
                dst.worldbody.remove(el)
                src.worldbody[0].set("user", [k, i])
                dst.findall(".//geom")
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert not any(t.is_alive() for t in threads), "deadlock"
    assert not errors, errors


def _longest_pause_while(call) -> tuple[float, float]:
    """Runs `call` in a thread; returns (its duration, the longest gap between two ticks
    of this thread meanwhile). With the GIL held for the whole call, the gap is the call."""
    done = threading.Event()
    took = []

    def worker():
        t = time.perf_counter()
        call()
        took.append(time.perf_counter() - t)
        done.set()

    thread = threading.Thread(target=worker)
    last = time.perf_counter()
    longest = 0.0
    thread.start()
    while not done.is_set():
        now = time.perf_counter()
        longest = max(longest, now - last)
        last = now
    thread.join()
    return took[0], longest


def test_long_calls_release_the_gil():
    # One document of 300,000 bodies: loading, writing and validating it each take tens
    # of milliseconds (writing it took 18 ms for half as many on a quiet machine), so a
    # call holding the GIL would stop this thread's ticks for that long, far more than
    # the OS's usual scheduling gaps.
    xml = "<mujoco><worldbody>" + "".join(
        f'<body name="b{i}"><geom size="0.1"/></body>' for i in range(300_000)
    ) + "</worldbody></mujoco>"
    calls = {
        "from_string": lambda: Document.from_string(xml),
        "to_xml": (lambda d: lambda: d.to_xml(pretty=True))(Document.from_string(xml)),
        "validate": (lambda d: lambda: d.validate())(Document.from_string(xml)),
    }
    for name, call in calls.items():
        # A call that held the GIL would stop the ticks for its whole length every time;
        # a busy machine can also stop them (the scheduler), but not three times running,
        # so the best of three attempts decides.
        attempts = [_longest_pause_while(call) for _ in range(3)]
        assert all(took > 0.02 for took, _ in attempts), (name, attempts)  # long enough to tell
        assert any(longest < took / 2 for took, longest in attempts), (name, attempts)
