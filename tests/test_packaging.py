"""printgen as an installed package (issue 21): where profiles and examples are found, the
commands a wheel offers. scripts/test_wheel.sh checks the same on a real wheel in a fresh venv."""

from __future__ import annotations

import importlib.resources
from pathlib import Path

import pytest

import printgen
from printgen.cli import main
from printgen.commands import bench
from printgen.inputs import profiles
from printgen.inputs.materials import load_material

ROOT = Path(__file__).resolve().parents[1]


def _material(root: Path, name: str, inherits: str = "petg") -> Path:
    p = root / "materials" / f"{name}.toml"
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(f'inherits = "{inherits}"\n')
    return p


def test_order_env_then_user_folder_then_bundled(tmp_path, monkeypatch):
    env, user = tmp_path / "env", tmp_path / "user"
    monkeypatch.setattr(profiles, "user_dir", lambda: user)
    monkeypatch.setenv("PRINTGEN_PROFILES", str(env))
    assert profiles.search_dirs() == [env, user, profiles.BUNDLED]
    assert profiles.profile_path("materials", "petg") == profiles.BUNDLED / "materials/petg.toml"
    mine = _material(user, "petg", inherits="pla")  # the user's petg hides the bundled one
    assert profiles.profile_path("materials", "petg") == mine
    assert _material(env, "petg", inherits="abs") == profiles.profile_path("materials", "petg")
    _material(user, "petg-lab")
    assert "petg-lab" in profiles.list_profiles("materials")
    assert load_material("petg-lab").name == load_material("petg").name  # inherited, merged


def test_the_user_folder_is_platformdirs_config_folder():
    from platformdirs import user_config_path

    assert profiles.user_dir() == user_config_path("printgen", appauthor=False) / "profiles"


def test_bundled_profiles_are_package_data_when_installed(tmp_path, monkeypatch):
    """In a checkout printgen/profiles does not exist and the top-level folder is used; an
    installed wheel has printgen/profiles (setup.py copies it in) and that is used."""
    assert profiles.BUNDLED == ROOT / "profiles"
    assert profiles.bundled_dir("examples") == ROOT / "examples"
    (tmp_path / "profiles").mkdir()
    monkeypatch.setattr(importlib.resources, "files", lambda pkg: tmp_path)
    assert profiles.bundled_dir() == tmp_path / "profiles"


def test_profiles_list_is_never_silently_empty(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(profiles, "BUNDLED", tmp_path / "gone")
    monkeypatch.setattr(profiles, "user_dir", lambda: tmp_path / "user")
    monkeypatch.delenv("PRINTGEN_PROFILES", raising=False)
    assert main(["profiles", "list"]) == 2
    err = capsys.readouterr().err
    assert "no materials, printers, prints profiles found; looked in" in err
    assert str(tmp_path / "gone") in err and "PRINTGEN_PROFILES is not set" in err
    assert main(["profiles", "list", "--kind", "printers", "--json"]) == 2


def test_example_prints_the_bundled_file(capsysbinary):
    assert main(["example", "realistic"]) == 0
    assert capsysbinary.readouterr().out == (ROOT / "examples/realistic_barrier.toml").read_bytes()
    assert main(["example"]) == 0
    assert b"simple\tsimple_barrier.toml" in capsysbinary.readouterr().out


def test_example_folder_is_copied_whole(tmp_path, capsys):
    """The paper's printed design and its measured test are an example folder: `--out` copies
    its files into a new folder and refuses one that exists."""
    out = tmp_path / "paper"
    assert main(["example", "paper_1_40", "--out", str(out)]) == 0
    for name in ("design.json", "measured.csv"):
        assert (out / name).read_bytes() == (ROOT / "examples/paper_1_40" / name).read_bytes()
    assert main(["example", "paper_1_40", "--out", str(out)]) == 2
    assert "exists; name a new folder" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["paper"]  # no stage left


def test_unknown_example_exits_2(capsys):
    assert main(["example", "nope"]) == 2
    assert ("no example named 'nope'; examples: realistic, simple, calibration, paper_1_40, "
            "notebook" in capsys.readouterr().err)


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out == f"printgen {printgen.__version__}\n"


def test_bench_is_offered_only_in_a_checkout(tmp_path, monkeypatch, capsys):
    assert bench.available()
    monkeypatch.setattr(bench, "ROOT", tmp_path)  # where an installed wheel's ROOT points
    assert main(["bench", "make"]) == 2  # a usage error: one line, exit 2
    assert "invalid choice: 'bench'" in capsys.readouterr().err


def test_example_out_leaves_a_users_folder_beside_it(tmp_path, capsys):
    """A folder the user keeps under the name an older stage had is never removed."""
    mine = tmp_path / ".ex.example-tmp"
    mine.mkdir()
    (mine / "notes.txt").write_text("mine")
    assert main(["example", "paper_1_40", "--out", str(tmp_path / "ex")]) == 0
    assert (mine / "notes.txt").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == [".ex.example-tmp", "ex"]


def test_example_and_init_take_json(tmp_path, capsys):
    import json

    assert main(["example", "--json"]) == 0
    assert "paper_1_40" in json.loads(capsys.readouterr().out)["examples"]
    assert main(["example", "realistic", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["text"].startswith("#")
    assert main(["init", str(tmp_path / "p.toml"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == {"written": str(tmp_path / "p.toml")}


def test_example_file_writes_a_one_file_example(tmp_path, capsys):
    """`printgen example NAME FILE`: no shell redirect needed; never over a file, never for a
    folder of files, never with --out too."""
    proto = tmp_path / "proto.toml"
    assert main(["example", "realistic", str(proto)]) == 0
    assert proto.read_bytes() == (ROOT / "examples/realistic_barrier.toml").read_bytes()
    assert capsys.readouterr().out.strip() == str(proto)
    assert main(["example", "simple", str(proto)]) == 2
    assert f"{proto} exists; name a new file" in capsys.readouterr().err
    assert main(["example", "paper_1_40", str(tmp_path / "p.toml")]) == 2
    assert "is a folder of files; copy it with `printgen example paper_1_40 --out DIR`" in \
        capsys.readouterr().err
    assert main(["example", "simple", str(tmp_path / "s.toml"), "--out", str(tmp_path / "o")]) == 2
    assert "give FILE or --out DIR, not both" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["proto.toml"]
