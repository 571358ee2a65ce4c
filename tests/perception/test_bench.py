"""perception.bench: the photo case and its stage breakdown."""

import perception


def test_photo_figures_wall_cpu_and_stages():
    out = perception.bench(frames=8)
    for size in ("320x240", "640x480"):
        assert out[f"fps_photos_{size}_cold"] > 0 and out[f"cpu_fps_photos_{size}_cold"] > 0
    stages = out["ms_photos_320x240_cold"]
    assert set(stages) == {"faces", "saliency", "colour"} and min(stages.values()) > 0
    assert out["faces_found"] >= 90 and out["false_detections"] == 0
