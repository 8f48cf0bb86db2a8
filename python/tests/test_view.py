"""clothcd.view: the same page as `clothcd view` from the same arguments, for a simulation folder
and for a detection step; bad arguments raise InputError and write nothing."""

import pytest

import clothcd
from conftest import cli


def page_data(path):
    text = path.read_text()
    start = text.index('<script id="clothcd-data"')
    return text[text.index(">", start) + 1:text.index("</script>", start)]


def test_view_writes_the_page_the_cli_writes(tmp_path, tiny_scene):
    clothcd.simulate(tiny_scene, tmp_path / "run", frames=2)
    s = clothcd.view(tmp_path / "run", out=tmp_path / "py.html")
    assert s["frames"] == 3 and s["body"] and s["strain"] and s["contact"]
    assert s["bytes"] == (tmp_path / "py.html").stat().st_size
    assert 0 < s["packed_bytes"] < s["data_bytes"]
    done = cli("view", str(tmp_path / "run"), "--out", str(tmp_path / "cli.html"))
    assert done.returncode == 0, done.stderr
    assert page_data(tmp_path / "py.html") == page_data(tmp_path / "cli.html")
    last = clothcd.view(tmp_path / "run", out=tmp_path / "last.html", first=2, no_body=True,
                        no_contact=True)
    assert last["frames"] == 1 and not last["body"] and not last["contact"]


def test_view_of_a_detection_step(tmp_path):
    a = tmp_path / "a.obj"
    b = tmp_path / "b.obj"
    a.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0.2 0.2 0.5\nv 1.2 0.2 0.5\nv 0.2 1.2 0.5\n"
                 "f 1 2 3\nf 4 5 6\n")
    b.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0.2 0.2 -0.5\nv 1.2 0.2 -0.5\nv 0.2 1.2 -0.5\n"
                 "f 1 2 3\nf 4 5 6\n")
    done = cli("detect", "--t0", str(a), "--t1", str(b), "--json", str(tmp_path / "r.json"))
    assert done.returncode == 0, done.stderr
    s = clothcd.view(t0=a, t1=b, json=tmp_path / "r.json", out=tmp_path / "step.html")
    assert s["hits"] > 0 and s["frames"] == 2


def test_bad_arguments_raise_and_write_nothing(tmp_path):
    out = tmp_path / "page.html"
    with pytest.raises(clothcd.InputError, match="either a simulation folder"):
        clothcd.view(out=out)
    with pytest.raises(clothcd.InputError, match="needs t0, t1 and json"):
        clothcd.view(t0=tmp_path / "a.obj", out=out)
    with pytest.raises(clothcd.InputError, match="not a folder"):
        clothcd.view(tmp_path / "nowhere", out=out)
    assert not out.exists()
