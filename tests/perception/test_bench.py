"""bench/perception_speed.py: the photo case, its stage breakdown and the two-thread figures."""

import threading
import time

import pytest

from bench.perception_speed import FreeCoresPool, bench

pytestmark = pytest.mark.slow  # every test here takes a second or more


def test_photo_figures_wall_cpu_and_stages():
    out = bench(frames=8)
    for size in ("320x240", "640x480"):
        for key in ("fps_photos_{}_cold", "cpu_fps_photos_{}_cold", "fps_photos_{}_cold_2threads",
                    "cpu_fps_photos_{}_cold_2threads", "free_cores_fps_photos_{}_cold_2threads"):
            assert out[key.format(size)] > 0, key
    stages = out["ms_photos_320x240_cold"]
    assert set(stages) == {"faces", "saliency", "colour"} and min(stages.values()) > 0
    # the quality figures the speed work keeps (98 / 100 lfw faces, 0 false, 191 / 192 poses)
    assert out["faces_found"] >= 98 and out["false_detections"] == 0
    assert out["pose_frames"] == 192 and out["poses_right"] >= 191


def _burn(seconds: float) -> float:
    start = time.thread_time()
    while time.thread_time() - start < seconds:
        pass
    return seconds


def test_free_cores_clock_replays_a_fifo_pool_from_cpu_times():
    two, one = FreeCoresPool(2), FreeCoresPool(1)
    try:
        for pool, expected in ((two, 0.1), (one, 0.2)):
            pool.restart()
            tasks = [pool.submit(_burn, 0.05) for _ in range(4)]
            assert [t.result() for t in tasks] == [0.05] * 4
            assert expected <= pool.elapsed() < expected + 0.04
        # a task cancelled before it starts costs nothing; the caller's own CPU time counts.
        # The first two hold both workers until the late ones are cancelled, so which late
        # tasks run does not depend on how fast this thread is scheduled.
        two.restart()
        gate = threading.Event()
        first = [two.submit(_burn_then_wait, 0.05, gate) for _ in range(2)]
        late = [two.submit(_burn, 0.05) for _ in range(10)]
        assert all(t.cancel() for t in late[3:])
        gate.set()
        first[0].result()
        first[1].result()
        ran = late[:3]
        for t in ran:
            t.result()
        _burn(0.02)
        expected = 0.05 + 0.05 * 2 + 0.02  # three late tasks on two workers after the first two
        assert expected <= two.elapsed() < expected + 0.04
    finally:
        two.shutdown()
        one.shutdown()


def _burn_then_wait(seconds: float, gate: threading.Event) -> float:
    _burn(seconds)
    gate.wait()  # blocked, not burning: no thread CPU time
    return seconds
