"""The Python module `trilux` against the `trilux` command.

Run from anywhere with the module installed and the command built
(`cargo build --release`; TRILUX_BIN names another binary). Every image
the command makes is read back with `trilux.read_exr`; the expected values
are the command's own outputs for the same settings (the orchestration is
shared, so a seeded render is the same image), the scene's film size, and
the API's documented errors.
"""

import os
import pathlib
import subprocess

import numpy as np
import pytest

import trilux

ROOT = pathlib.Path(__file__).resolve().parents[3]
CORNELL = ROOT / "scenes" / "cornell-box.xml"
BIN = pathlib.Path(os.environ.get("TRILUX_BIN", ROOT / "target" / "release" / "trilux"))

# A small, quick render of the bundled Cornell box.
SMALL = dict(spp=8, width=40, height=32, seed=3, quality="draft")


def command(*args):
    """Runs the trilux command; returns its completed process (checked)."""
    if not BIN.is_file():
        pytest.fail(f"the trilux command is not built at {BIN} (cargo build --release)")
    done = subprocess.run([str(BIN), *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def command_render(tmp_path, scene, name="cli.exr", extra=()):
    """The command's EXR of `scene` with SMALL's settings, as an array."""
    out = tmp_path / name
    command(
        "render", scene, "-o", out,
        "--spp", SMALL["spp"], "--width", SMALL["width"], "--height", SMALL["height"],
        "--seed", SMALL["seed"], "--quality", SMALL["quality"], *extra,
    )
    return trilux.read_exr(out)


def test_import():
    assert isinstance(trilux.__version__, str)
    assert issubclass(trilux.TriluxError, Exception)
    for name in ["load", "load_solution", "render", "bake", "read_exr", "Scene", "Solution"]:
        assert hasattr(trilux, name), name


def test_render_matches_the_command(tmp_path):
    ours = trilux.render(str(CORNELL), **SMALL)
    assert ours.shape == (32, 40, 3)
    assert ours.dtype == np.float32
    assert ours.flags["C_CONTIGUOUS"]
    # Finite; spectra outside the sRGB gamut may come out a little negative.
    assert np.isfinite(ours).all() and ours.mean() > 0
    theirs = command_render(tmp_path, CORNELL)
    assert theirs.shape == ours.shape
    # The mean within 1 % of the command's, channel by channel.
    for c in range(3):
        assert abs(ours[..., c].mean() / theirs[..., c].mean() - 1) < 0.01, c
    # Not merely close: the same orchestration with the same seed.
    np.testing.assert_array_equal(ours, theirs)
    # The light is where the Cornell box has it: the red left wall is redder
    # than the green right wall, and the picture is not flat.
    left, right = ours[:, :8].mean(axis=(0, 1)), ours[:, -8:].mean(axis=(0, 1))
    assert left[0] > left[1] and right[1] > right[0]
    assert ours.std() > 0.05 * ours.mean()


def test_a_path_object_and_a_scene_render_alike():
    a = trilux.render(CORNELL, **SMALL)
    b = trilux.render(trilux.load(CORNELL), **SMALL)
    np.testing.assert_array_equal(a, b)
    c = trilux.render(CORNELL, **{**SMALL, "seed": 4})
    assert not np.array_equal(a, c), "another seed, other samples"


def test_defines_and_the_scenes_own_film():
    scene = trilux.load(str(CORNELL), defines={"res": 24, "spp": "2"})
    assert scene.film == (24, 24)
    assert scene.shapes == 8 and scene.emitters == 1
    assert scene.mode == "spectral"
    image = trilux.render(scene, quality="draft")
    assert image.shape == (24, 24, 3)


def test_solutions_save_load_and_render_as_the_command(tmp_path):
    scene = trilux.load(CORNELL)
    solution = scene.solve(quality="draft")
    assert 0.95 <= solution.convergence_ratio <= 1.0
    assert solution.stats()["convergence_ratio"] == solution.convergence_ratio
    path = tmp_path / "box.sol"
    solution.save(path)
    loaded = trilux.load_solution(CORNELL, path, quality="draft")
    view = {k: v for k, v in SMALL.items() if k != "quality"}
    from_memory = trilux.render(scene, solution=solution, **view)
    from_file = trilux.render(CORNELL, solution=loaded, **view)
    np.testing.assert_array_equal(from_memory, from_file)
    # The command reads the file and renders the same image from it.
    theirs = command_render(tmp_path, CORNELL, "from-sol.exr", ["--solution", path])
    np.testing.assert_array_equal(from_file, theirs)
    # A solution made with other settings is refused, naming the file.
    with pytest.raises(trilux.TriluxError, match="box.sol"):
        trilux.load_solution(CORNELL, path, quality="default")
    # A solution renders its own scene only.
    with pytest.raises(ValueError, match="its own scene"):
        trilux.render(ROOT / "scenes" / "furnace.xml", solution=solution)


def test_bake(tmp_path):
    glb = tmp_path / "box.glb"
    stats = trilux.bake(CORNELL, glb, quality="draft")
    data = glb.read_bytes()
    assert data[:4] == b"glTF"
    assert stats["bytes"] == len(data)
    assert stats["triangles"] > 0 and stats["vertices"] > 0
    with pytest.raises(ValueError, match=r"\.glb"):
        trilux.bake(CORNELL, tmp_path / "box.gltf")
    assert not (tmp_path / "box.gltf").exists()


def test_a_missing_file_raises_with_its_path(tmp_path):
    missing = tmp_path / "no-such-scene.xml"
    for call in (lambda: trilux.load(missing), lambda: trilux.render(missing, spp=1)):
        with pytest.raises(trilux.TriluxError, match="no-such-scene.xml"):
            call()


def test_a_malformed_file_raises_at_its_place(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text('<scene version="3.0.0">\n  <shape type="rectangle">\n</scene>\n')
    with pytest.raises(trilux.TriluxError) as caught:
        trilux.load(bad)
    message = str(caught.value)
    assert message.startswith(f"{bad}:3:"), message
    assert "malformed XML" in message
    # The command says the same thing.
    done = subprocess.run([str(BIN), "info", str(bad)], capture_output=True, text=True)
    assert done.returncode == 1
    assert done.stderr.strip() == f"error: {message}"


def test_an_unused_define_raises_as_in_mitsuba():
    with pytest.raises(trilux.TriluxError, match="nope=1 is not used"):
        trilux.load(CORNELL, defines={"nope": 1})
    with pytest.raises(ValueError, match="parameter name"):
        trilux.load(CORNELL, defines={"not a name": 1})


@pytest.mark.parametrize(
    "kwargs",
    [
        {"spp": 0},
        {"spp": -1},
        {"spp": 1 << 40},
        {"width": 0},
        {"height": 10**9},
        {"seed": -1},
        {"quality": "fast"},
        {"convergence": 1.5},
        {"convergence": float("nan")},
        {"mode": "hdr"},
    ],
)
def test_bad_arguments_raise_value_error_before_any_work(kwargs, tmp_path):
    # The scene does not exist: a ValueError (not a TriluxError about the
    # file) shows the argument was checked first.
    with pytest.raises(ValueError):
        trilux.render(tmp_path / "missing.xml", **kwargs)


def test_a_scene_of_the_wrong_type_raises_type_error():
    with pytest.raises(TypeError):
        trilux.render(42)


def test_the_readme_comparison_with_mitsuba():
    """The README's side-by-side: trilux and Mitsuba 3 on the Cornell box
    agree in the mean (the golden test holds them within 1 % at full size;
    64 × 64 pixels at 64 spp leave Mitsuba's mean a little noise)."""
    mi = pytest.importorskip("mitsuba")
    mi.set_variant("scalar_spectral")
    spp, res = 64, 64
    ours = trilux.render(CORNELL, spp=spp, width=res, height=res)
    ref = np.array(mi.render(mi.load_file(str(CORNELL), spp=spp, res=res)))[..., :3]
    assert ours.shape == ref.shape
    assert abs(ours.mean() / ref.mean() - 1) < 0.03
