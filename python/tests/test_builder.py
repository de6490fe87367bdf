"""The builder (mirroring the Rust one) and raw bond graphs from Python dicts."""

from __future__ import annotations

import json

import numpy as np
import pytest

import bondmech
from bondmech import Ground, Mechanism, PlanarBody, SpringDamper
from conftest import SCENES


def double_pendulum_in_code() -> bondmech.Scene:
    # the numbers of scenes/double_pendulum.json, inertia as written there
    j = 0.0833333333333333
    bar = lambda name, x: (PlanarBody(name, 1.0, j).point("O", [-0.5, 0.0])
                           .point("A", [0.5, 0.0]).at([x, 0.0], 0.0))
    return (Mechanism.planar().name("double_pendulum").gravity([0.0, -9.81])
            .body(bar("bar1", 0.5)).body(bar("bar2", 1.5))
            .revolute("pivot", Ground.at([0.0, 0.0]), ("bar1", "O"))
            .revolute("knee", ("bar1", "A"), ("bar2", "O"))
            .output("bar2.A").output("energy").output("constraint_error")
            .t_end(3.0).output_step(0.01).tolerances(1e-8, 1e-10).formulation("dae")
            .build())


def test_builder_scene_solves_exactly_like_the_scene_file(double_pendulum_path):
    built = double_pendulum_in_code()
    assert isinstance(built, bondmech.Scene) and built.name == "double_pendulum"
    a = built.run(t_end=1.0)
    b = bondmech.load(double_pendulum_path).run(t_end=1.0)
    assert a.columns == b.columns
    assert np.array_equal(a.values, b.values)


def test_builder_is_immutable_and_reusable():
    base = Mechanism.planar().gravity([0, -9.81]).body(PlanarBody.bar("bar", 1.0, 1.0).at([0.5, 0]))
    one = base.revolute("pivot", Ground.at([0, 0]), ("bar", "O")).t_end(0.5).build()
    # base itself has no joint: a free body falls
    free = base.t_end(0.5).build().run()
    pinned = one.run()
    assert free["bar.y"][-1] == pytest.approx(-0.5 * 9.81 * 0.25, rel=1e-6)
    assert abs(pinned["bar.y"][-1]) < 1.0


def test_builder_errors_name_the_element():
    with pytest.raises(bondmech.SceneError) as info:
        Mechanism.planar().body(PlanarBody.point_mass("bob", -1.0)).build()
    paths = [p["path"] for p in info.value.problems]
    assert "body 'bob' (bodies[0]).mass" in paths and "solve.t_end" in paths
    assert "body 'bob'" in str(info.value)
    with pytest.raises(TypeError):
        Mechanism.planar().revolute("j", 42, ("bob", "O"))
    with pytest.raises(ValueError):
        Mechanism.planar().formulation("nope")


def test_slider_crank_in_code_equals_the_scene_file():
    # scenes/slider_crank.json written with the builder (points named, loads as expressions)
    raw = json.loads((SCENES / "slider_crank.json").read_text())
    bodies = {b["name"]: b for b in raw["bodies"]}
    mech = Mechanism.planar().name("slider_crank").gravity(raw["gravity"])
    for name in ("crank", "rod", "piston"):
        b = bodies[name]
        body = PlanarBody(name, b["mass"], b["inertia"])
        for p, xy in b["points"].items():
            body = body.point(p, xy)
        mech = mech.body(body.at(b["position"], b["angle"]))
    scene = (mech.revolute("main_bearing", Ground.at([0.0, 0.0]), ("crank", "O"))
             .revolute("crank_pin", ("crank", "A"), ("rod", "A"))
             .revolute("wrist_pin", ("rod", "B"), ("piston", "P"))
             .prismatic("cylinder", Ground.at([0.0, 0.0]), ("piston", "P"), [0.0, 1.0])
             .torque("drive", "crank", 1.5)
             .force("gas", ("piston", "P"), ["0", "-10*max(0, cos(crank.angle))"])
             .output("piston.P").output("crank.A").output("energy").output("constraint_error")
             .t_end(1.0).output_step(0.001).tolerances(1e-8, 1e-10).build())
    a = scene.run(t_end=0.2)
    b = bondmech.load(SCENES / "slider_crank.json").run(t_end=0.2)
    assert a.columns == b.columns and np.array_equal(a.values, b.values)
    assert np.max(np.abs(a["piston.x"])) < 1e-9  # the cylinder holds the piston on its axis
    # a spring-damper between the ground and the piston changes the motion
    sprung = (Mechanism.planar().body(PlanarBody("m", 1.0, 0.01).at([0.0, -0.1]))
              .prismatic("rail", Ground.at([0.0, 0.0]), "m", [0.0, 1.0])
              .spring(SpringDamper("k", Ground.at([0.0, 0.0]), "m", 4.0).rest_length(0.0))
              .t_end(np.pi / 4).build().run(rtol=1e-10, atol=1e-12))
    # m y'' = -k y: a quarter period of ω = 2 from y = -0.1 at rest reaches y = 0
    assert abs(sprung["m.y"][-1]) < 1e-6 and abs(sprung["m.vy"][-1] - 0.2) < 1e-6


def test_raw_bond_graph_from_a_dict_matches_the_closed_form():
    # mass-spring-damper as a bond graph: Se → 1-junction with I (m), C (k), R (b)
    m, k, b, x0 = 1.5, 6.0, 0.3, 0.1
    graph = {
        "bond_graph": {
            "elements": [
                {"name": "F", "kind": "Se", "value": 0.0},
                {"name": "v", "kind": "1"},
                {"name": "m", "kind": "I", "value": m},
                {"name": "k", "kind": "C", "stiffness": k, "initial": x0},
                {"name": "b", "kind": "R", "value": b},
            ],
            "bonds": [{"from": "F", "to": "v"}, {"from": "v", "to": "m"},
                      {"from": "v", "to": "k"}, {"from": "v", "to": "b"}],
        },
        "solve": {"t_end": 10.0, "output_step": 0.05, "rtol": 1e-10, "atol": 1e-12},
    }
    scene = bondmech.load(graph)
    assert scene.is_bond_graph
    report = bondmech.graph(scene, causality=True)
    assert report["dof"] == 1 and report["state_count"] == 2
    sol = scene.run()
    w0 = np.sqrt(k / m)
    zeta = b / (2 * m * w0)
    wd = w0 * np.sqrt(1 - zeta**2)
    t = sol.t
    exact = np.exp(-zeta * w0 * t) * (x0 * np.cos(wd * t) + zeta * w0 * x0 / wd * np.sin(wd * t))
    assert np.max(np.abs(sol["q_k"] - exact)) < 1e-7
    # the same graph with the damper doubled is told apart
    graph["bond_graph"]["elements"][4]["value"] = 2 * b
    assert np.max(np.abs(bondmech.load(graph).run()["q_k"] - exact)) > 1e-3
