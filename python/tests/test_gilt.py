"""Tests of the Python module: the same entry points as the command line, so the same image."""
import os
import signal
import subprocess
import sys
import tempfile
import threading

import numpy as np
import pytest

import gilt


def test_render_cornell_to_numpy():
    scene = gilt.Scene("cornell")
    image, stats = gilt.render(scene, spp=4, width=32, height=24, threads=2)
    assert image.dtype == np.float32 and image.shape == (24, 32, 3)
    assert np.isfinite(image).all() and image.min() >= 0.0
    assert image.mean() > 0.01  # the box is lit
    assert stats["spp"] == 4 and stats["width"] == 32 and stats["method"] == "path"
    assert stats["rays"] > 32 * 24 * 4


def test_same_image_as_the_command_line():
    """gilt.render and `gilt render` call one library function: their EXR pixels are equal."""
    binary = os.environ.get("GILT_BINARY")
    if not binary:
        pytest.skip("GILT_BINARY (the gilt tool) not given")
    oiio = pytest.importorskip("OpenImageIO")
    scene = gilt.Scene("cornell-caustics")
    image, _ = gilt.render(scene, method="sppm", spp=2, width=24, height=16, seed=5, threads=1)
    with tempfile.TemporaryDirectory() as folder:
        out = os.path.join(folder, "sppm.exr")
        subprocess.run([binary, "render", "cornell-caustics", "--method", "sppm", "--spp", "2", "--width", "24",
                        "--height", "16", "--seed", "5", "--threads", "2", "-q", "-o", out], check=True)
        pixels = oiio.ImageInput.open(out).read_image(oiio.FLOAT)
    np.testing.assert_array_equal(image, np.asarray(pixels, dtype=np.float32)[:, :, :3])


def test_every_method_and_the_camera_override():
    scene = gilt.Scene("cornell")
    default = scene.camera
    scene.camera = gilt.Camera(look_from=(278, 273, -600), look_at=(278, 273, 0), vfov=50)
    assert scene.camera.look_from == (278.0, 273.0, -600.0) and default.look_from != scene.camera.look_from
    ortho = gilt.Camera(look_from=(278, 273, -800), look_at=(278, 273, 0), ortho_height=600)
    assert ortho.orthographic and ortho.ortho_height == 600
    scene.camera = ortho
    image, _ = gilt.render(scene, spp=1, width=16, height=16, threads=2)
    assert image.mean() > 0.0
    scene.camera = gilt.Camera(look_from=(278, 273, -600), look_at=(278, 273, 0), vfov=50)
    for method in gilt.METHODS:
        image, stats = gilt.render(scene, method=method, spp=1, width=16, height=16, threads=2, photons=20000,
                                   elements=500)
        assert image.shape == (16, 16, 3) and np.isfinite(image).all(), method
        assert image.mean() > 0.0, method


def test_deterministic_across_threads():
    scene = gilt.Scene("cornell")
    a, _ = gilt.render(scene, spp=3, width=20, height=20, seed=9, threads=1)
    b, _ = gilt.render(scene, spp=3, width=20, height=20, seed=9, threads=2)
    np.testing.assert_array_equal(a, b)


def test_radiosity_arrays():
    result = gilt.radiosity(gilt.Scene("cornell"), elements=500, threads=2)
    positions, indices, radiosity = result["positions"], result["indices"], result["radiosity"]
    assert positions.shape[1] == 3 and indices.shape[1] == 3 and radiosity.shape == positions.shape
    assert indices.dtype == np.uint32 and indices.max() < len(positions)
    assert np.isfinite(radiosity).all() and radiosity.min() >= 0.0
    assert result["stats"]["elements"] == len(indices)
    assert result["stats"]["residual"] <= 1e-3


def test_compare_returns_metrics():
    with tempfile.TemporaryDirectory() as folder:
        os.environ["GILT_CACHE_DIR"] = folder
        metrics = gilt.compare(gilt.Scene("cornell"), methods=["path", "radiosity"], budgets=[0.3], width=24,
                               height=24, reference_time=1.0, threads=2, output=os.path.join(folder, "report"))
        assert os.path.exists(os.path.join(folder, "report", "metrics.json"))
    assert [m["method"] for m in metrics] == ["path", "radiosity"]
    for m in metrics:
        assert m["budget_seconds"] == 0.3 and m["spp_or_iterations"] >= 1
        assert 0.5 < m["mean_ratio"] < 2.0 and np.isfinite(m["relmse"])


def test_bad_input_raises_value_error():
    with pytest.raises(ValueError, match="no-such-file"):
        gilt.Scene("no-such-file.obj")
    scene = gilt.Scene("cornell")
    with pytest.raises(ValueError, match="method"):
        gilt.render(scene, method="rasterise", spp=1, width=8, height=8)
    with pytest.raises(ValueError):
        gilt.render(scene, spp=1, time=1.0)
    with pytest.raises(ValueError, match="look_from"):
        gilt.Camera(look_from=(0, 0), look_at=(0, 0, 1))
    with pytest.raises(ValueError, match="methods"):
        gilt.compare(scene, methods=["nope"], budgets=[1])
    with pytest.raises(ValueError, match="alpha"):
        gilt.render(scene, method="sppm", spp=1, width=8, height=8, alpha=1.5)
    with pytest.raises(ValueError, match="radiosity_view"):
        gilt.render(scene, method="radiosity", spp=1, width=8, height=8, radiosity_view="wireframe")


def test_the_gil_is_released_during_a_render():
    """Another Python thread keeps running while a render does."""
    scene = gilt.Scene("cornell")
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            stop.wait(0.005)

    counter = threading.Thread(target=count)
    counter.start()
    gilt.render(scene, time=0.5, width=64, height=64, threads=1)
    stop.set()
    counter.join()
    assert len(ticks) > 20  # about 100 in 0.5 s; none if the render held the GIL


def test_ctrl_c_interrupts_a_render():
    """SIGINT during a long render raises KeyboardInterrupt promptly, and the module stays usable."""
    script = (
        "import gilt, os, signal, threading, time\n"
        "scene = gilt.Scene('cornell')\n"
        "threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()\n"
        "start = time.time()\n"
        "try:\n"
        "    gilt.render(scene, spp=100000, width=64, height=64, threads=1)\n"
        "    print('finished')\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted after %.1f s' % (time.time() - start))\n"
        "image, stats = gilt.render(scene, spp=1, width=8, height=8)\n"
        "print('usable', stats['spp'])\n")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                         env=dict(os.environ))
    assert out.returncode == 0, out.stderr
    lines = out.stdout.split("\n")
    assert lines[0].startswith("interrupted after"), out.stdout
    assert float(lines[0].split()[2]) < 5.0  # the full render would take minutes
    assert lines[1] == "usable 1"
