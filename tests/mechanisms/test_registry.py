"""optdesign/mechanisms/registry.py as a whole: the three ways to register, every refusal
with its field and words, replacing and re-registering, the look-up's message, and the
entry points (loaded once, a registered name kept, a broken plug-in named)."""

import importlib.metadata

import pytest

from optdesign import math as m
from optdesign.errors import InputError
from optdesign.mechanisms import registry
from optdesign.mechanisms.base import Mechanism
from optdesign.mechanisms.registry import get_mechanism, register_mechanism, registered
from optdesign.user_code import UserCodeError


@pytest.fixture(autouse=True)
def _registry_restored():
    saved, loaded = dict(registry._REGISTRY), registry._ENTRY_POINTS_LOADED
    yield
    registry._REGISTRY.clear()
    registry._REGISTRY.update(saved)
    registry._ENTRY_POINTS_LOADED = loaded


def _lever(name="reg_lever", **attrs):
    def nut_position(self, phi):
        return self.R * m.sin(phi)

    body = {
        "name": name,
        "variables": {"R": "length"},
        "pin_joints": (),
        "nut_position": nut_position,
        **attrs,
    }
    return type("Lever", (Mechanism,), body)


def test_the_three_ways_to_register():
    a = register_mechanism(_lever("reg_a"))
    assert get_mechanism("reg_a") is a
    b = register_mechanism(_lever("reg_b_class"))
    assert registry._REGISTRY["reg_b_class"] is b
    keyed = register_mechanism("reg_keyed")(_lever("other_name"))
    assert keyed.name == "reg_keyed"
    assert get_mechanism("reg_keyed") is keyed
    assert "other_name" not in registry._REGISTRY
    named = register_mechanism()(_lever("reg_named"))
    assert get_mechanism("reg_named") is named


def test_what_is_no_mechanism_is_refused_naming_the_call():
    with pytest.raises(InputError) as err:
        register_mechanism(int)
    assert err.value.field == "register_mechanism"
    assert "<class 'int'> is not a Mechanism subclass" in str(err.value)
    with pytest.raises(InputError) as err:
        register_mechanism(5)
    assert err.value.field == "register_mechanism"
    assert "5 is not a Mechanism subclass (or a name)" in str(err.value)
    with pytest.raises(InputError) as err:
        register_mechanism("reg_x")(object())
    assert err.value.field == "register_mechanism"


def test_a_class_without_a_name_is_refused():
    for name in ("", None):
        with pytest.raises(InputError) as err:
            register_mechanism(_lever(name))
        assert err.value.field == "mechanism"
        assert "Lever has no name; set name = '...'" in str(err.value)


def test_a_second_class_under_a_name_needs_replace_unless_it_is_the_same():
    first = register_mechanism(_lever("reg_twice"))
    assert register_mechanism(first) is first  # the same class again

    class Other(_lever("reg_twice")):
        pass

    with pytest.raises(InputError) as err:
        register_mechanism(Other)
    assert err.value.field == "mechanism"
    assert (
        f"'reg_twice' is registered already ({first.__module__}.Lever); pass replace=True"
        in str(err.value)
    )
    assert get_mechanism("reg_twice") is first
    assert register_mechanism(replace=True)(Other) is Other
    assert get_mechanism("reg_twice") is Other
    # A class of the same qualified name (a module reloaded in a notebook) replaces it.
    reloaded = _lever("reg_twice")
    reloaded.__qualname__ = Other.__qualname__
    assert register_mechanism(reloaded) is reloaded
    assert get_mechanism("reg_twice") is reloaded


def test_bad_declarations_are_refused_when_registered_naming_the_class():
    with pytest.raises(UserCodeError) as err:
        register_mechanism(_lever("reg_bad_vars", variables={"R": "mass"}))
    assert "mechanism 'reg_bad_vars' (class " in str(err.value)
    assert ": its variables: InputError:" in str(err.value) and "'mass'" in str(err.value)
    assert err.value.subject.startswith("mechanism 'reg_bad_vars' (class ")
    assert "reg_bad_vars" not in registry._REGISTRY

    class NoKinematics(Mechanism):
        name = "reg_nokin"
        pin_joints = ()

    with pytest.raises(UserCodeError, match=r"define nut_position\(self, phi\)"):
        register_mechanism(NoKinematics)


def test_undeclared_pins_are_refused_unless_the_class_writes_its_chain():
    with pytest.raises(UserCodeError) as err:
        register_mechanism(_lever("reg_nopins", pin_joints=None))
    assert str(err.value).endswith(
        ": its pins are undeclared: set pin_joints = ('crank pin',) for pins on the screw's "
        "line of action carrying the nut force (a Scotch yoke's), pin_joints = () for none, "
        "or write joints(self, phi, M_h, pin) (docs/mechanisms.md)"
    )
    own_chain = _lever("reg_chain", pin_joints=None, joints=lambda self, phi, M_h, pin=None: [])
    assert register_mechanism(own_chain) is own_chain


@pytest.mark.parametrize("pins", [["a"], ("a", "a"), ("a", " "), ("a", 3), "pin"])
def test_pin_joints_must_be_a_tuple_of_distinct_names(pins):
    with pytest.raises(UserCodeError) as err:
        register_mechanism(_lever("reg_pins", pin_joints=pins))
    assert f"pin_joints must be a tuple of distinct names, got {pins!r}" in str(err.value)


def test_good_pin_declarations_register():
    for pins in ((), ("crank pin",), ("a", "b")):
        assert register_mechanism(_lever("reg_good", pin_joints=pins), replace=True)


def test_an_unknown_name_lists_the_registered_ones():
    with pytest.raises(InputError) as err:
        get_mechanism("no_such_linkage")
    assert err.value.field == "mechanism"
    names = registered()
    assert {"crank_slider", "fork", "pivoting_screw"} <= set(names)
    assert f"unknown mechanism 'no_such_linkage' (registered: {', '.join(names)})" in str(err.value)
    # how to add one: in Python, or as a package's entry point
    assert "@od.register_mechanism(NAME)" in str(err.value)
    assert "entry point of the group 'optdesign.mechanisms'" in str(err.value)
    with pytest.raises(InputError, match=r"; did you mean 'crank_slider'\? a mechanism of your"):
        get_mechanism("crank_slidr")


class _EntryPoint:
    def __init__(self, name, value, load):
        self.name, self.value, self._load = name, value, load
        self.loads = 0

    def load(self):
        self.loads += 1
        return self._load()


def test_entry_points_load_once_keep_registered_names_and_name_a_broken_plug_in(monkeypatch):
    plugin = _lever("ignored_name")
    eps = [
        _EntryPoint("crank_slider", "x:y", lambda: pytest.fail("a registered name is loaded")),
        _EntryPoint("ep_lever", "pkg.mod:Lever", lambda: plugin),
    ]
    groups = []

    def entry_points(group):
        groups.append(group)
        return eps

    monkeypatch.setattr(importlib.metadata, "entry_points", entry_points)
    registry._ENTRY_POINTS_LOADED = False
    assert get_mechanism("ep_lever") is plugin
    assert plugin.name == "ep_lever"
    assert groups == ["optdesign.mechanisms"]
    assert eps[1].loads == 1
    # loaded once per process: a second miss does not look again
    with pytest.raises(InputError):
        get_mechanism("still_missing")
    assert groups == ["optdesign.mechanisms"]

    def broken():
        raise ImportError("no module named pkg")

    eps[:] = [_EntryPoint("ep_broken", "pkg.mod:Broken", broken)]
    registry._ENTRY_POINTS_LOADED = False
    with pytest.raises(InputError) as err:
        get_mechanism("anything")
    assert err.value.field == "mechanism"
    assert "plug-in 'ep_broken' (pkg.mod:Broken) failed to load: no module named pkg" in str(
        err.value
    )


def test_a_registered_name_is_found_without_looking_at_entry_points(monkeypatch):
    monkeypatch.setattr(
        importlib.metadata, "entry_points", lambda group: pytest.fail("entry points read")
    )
    registry._ENTRY_POINTS_LOADED = False
    assert get_mechanism("crank_slider").name == "crank_slider"
    assert registry._ENTRY_POINTS_LOADED is False
