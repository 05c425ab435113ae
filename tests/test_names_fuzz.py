"""Fuzz: a profile or material name is a name, never a path (issue 20).

Random names (separators, `..`, NUL, glob characters, unicode, leading dots) go everywhere a
profile name is read: the profile lookup of each kind, `inherits`, a prototype's [model],
design.json, `profiles show`, `calibrate --material`/`--inherits` and the fitted profile of
`verify`. Each is either accepted as a plain name (and then only ever looked up inside the
profile folders) or refused with a ProfileError; no file outside the profile folders is read.
"""

from __future__ import annotations

import copy
import json
import re
import string
from pathlib import Path

import pytest
import tomli_w
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from proto_files import REALISTIC, prototype_dict

from printgen.errors import InputError, ProfileError
from printgen.inputs import profiles
from printgen.inputs.materials import load_material
from printgen.inputs.printers import load_print_style, load_printer
from printgen.inputs.profiles import BUNDLED, KINDS, profile_name

PLAIN = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,63}")  # the documented rule, written again
EXAMPLES = 40  # names per target: each refusal costs microseconds, an acceptance one lookup
TRICKY = "/\\.\x00*?[]{}~$:'\"\n -_"
names = st.one_of(
    st.text(alphabet=st.sampled_from(list(TRICKY + string.ascii_letters[:6] + "09")),
            max_size=12),
    st.text(max_size=12),  # any unicode
    st.sampled_from(["tpe", "petg", "generic-350", "net", "TPE", "a" * 64, "a" * 65]),
)
LOADERS = {"materials": load_material, "printers": load_printer, "prints": load_print_style}
SETTINGS = settings(max_examples=EXAMPLES, deadline=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])


def bait_examples(f):
    """The reproductions of the issue, tried on every target before the random names."""
    for name in ["../outside/tpe2", "../../outside/victim", "/etc/passwd", "/tmp/x/tpe2",
                 "tpe/../../x", "..", ".", ".tpe", "tpe\x00", "*", "t?e", "[t]pe", "~/tpe",
                 "C:\\x\\tpe", "tpé", "", " tpe"]:
        f = example(name=name)(f)
    return f


def fuzz_names(f):
    """The test over random names, the issue's reproductions first."""
    return bait_examples(given(name=names)(SETTINGS(f)))


@pytest.fixture
def reads(monkeypatch, tmp_path):
    """Every TOML path the profile lookup reads, with a profile folder of our own in front."""
    root = tmp_path / "profiles"
    for kind in KINDS:
        (root / kind).mkdir(parents=True)
    monkeypatch.setenv("PRINTGEN_PROFILES", str(root))
    seen: list[Path] = []
    real = profiles.load_toml

    def spy(path, *a, **kw):
        seen.append(Path(path))
        return real(path, *a, **kw)

    monkeypatch.setattr(profiles, "load_toml", spy)
    return root, seen


def inside_profile_folders(paths: list[Path], root: Path) -> bool:
    allowed = [(r / k).resolve() for r in (root, BUNDLED) for k in KINDS]
    return all(p.resolve().parent in allowed for p in paths)


def accepted_or_refused(call, name: str) -> None:
    """`call()` refuses an invalid name with ProfileError; a valid one may still be unknown."""
    try:
        call()
    except ProfileError as exc:
        if not PLAIN.fullmatch(name):
            assert "is not a" in str(exc), exc
        return
    assert PLAIN.fullmatch(name), f"{name!r} was accepted"


@pytest.mark.slow
@fuzz_names
def test_profile_lookup_of_every_kind(reads, name):
    root, seen = reads
    seen.clear()
    for kind in KINDS:
        accepted_or_refused(lambda kind=kind: LOADERS[kind](name), name)
    assert inside_profile_folders(seen, root), seen


@pytest.mark.slow
@fuzz_names
def test_inherits(reads, name):
    root, seen = reads
    seen.clear()
    (root / "materials" / "child.toml").write_text(tomli_w.dumps({"inherits": name}))
    try:
        load_material("child")
    except ProfileError as exc:
        assert PLAIN.fullmatch(name) or "inherits" in str(exc), exc
    except InputError:
        assert PLAIN.fullmatch(name)  # a real parent, but child.toml lacks required keys
    assert inside_profile_folders(seen, root), seen


@pytest.mark.slow
@fuzz_names
def test_prototype_model_names(tmp_path, name):
    from printgen.inputs.prototype import load_prototype

    for key in ("printer", "net_print", "cable_print", "materials"):
        data = copy.deepcopy(prototype_dict(REALISTIC))
        data["model"][key] = [name] if key == "materials" else name
        path = tmp_path / "p.toml"
        path.write_text(tomli_w.dumps(data))
        accepted_or_refused(lambda path=path: load_prototype(path), name)


@pytest.mark.slow
@fuzz_names
def test_design_json_names(design_1_40, name):
    from printgen.run.verify import fitted_name
    from printgen.scaling.design_file import design_from_dict

    base = design_1_40.to_dict()
    for where in (("printer",), ("net", "material"), ("net", "print_style"),
                  ("cables", 0, "material"), ("cables", 0, "name")):
        data = json.loads(json.dumps(base))
        node = data
        for k in where[:-1]:
            node = node[k]
        node[where[-1]] = name
        try:
            d = design_from_dict(data)
        except ProfileError:
            assert not PLAIN.fullmatch(name)
            continue
        except InputError as exc:  # plain, but a cable is named by its side, once per net
            assert where[-1] == "name" and ("one of" in str(exc) or "a second" in str(exc)), exc
            continue
        assert PLAIN.fullmatch(name)
        assert "/" not in fitted_name(d) and "\\" not in fitted_name(d)


@fuzz_names
def test_calibrate_material_and_profiles_show(tmp_path, capsys, name):
    import argparse

    from printgen.calibrate.pipeline import calibrate
    from printgen.commands.profiles import run_show
    from printgen.errors import CalibrationError

    def cal():
        with pytest.raises(CalibrationError, match="file not found"):  # after the name check
            calibrate([tmp_path / "missing.csv"], material=name)

    accepted_or_refused(cal, name)
    show = argparse.Namespace(name=name, kind=None, json=True)
    try:
        run_show(show)
    except ProfileError as exc:
        assert PLAIN.fullmatch(name) or "is not a profile name" in str(exc)
    else:
        assert PLAIN.fullmatch(name)
    capsys.readouterr()


BAIT = ["../outside/tpe2", "/etc/passwd", "..", ".tpe", "*", "a/b", "-x", "tpé"]


@pytest.mark.parametrize("name", BAIT)
def test_calibrate_command_refuses_path_names(tmp_path, capsys, name):
    from printgen.cli import main

    for opt in ("--material", "--inherits"):
        other = "--inherits=tpe" if opt == "--material" else "--material=lab"
        code = main(["calibrate", str(tmp_path / "missing.csv"), f"{opt}={name}", other,
                     "--out", str(tmp_path / "p"), "--plot", str(tmp_path / "plots")])
        err = capsys.readouterr().err
        assert code == 2 and f"{opt}: " in err and "is not a profile name" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_the_rule_is_the_documented_one():
    for good in ("tpe", "petg-lab", "tpu_95a", "generic-350", "a.b", "A1"):
        assert profile_name(good) == good
    for bad in ("", ".tpe", "-x", "/x", "a/b", "a\\b", "..", "a\x00", "é", "a b",
                "*", "a" * 65, 3, None):
        with pytest.raises(ProfileError):
            profile_name(bad)
