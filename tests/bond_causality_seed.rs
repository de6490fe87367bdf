//! The seed chapter's causality counts (sections 16.1, 16.5–16.8) as acceptance tests, built
//! both from hand-written raw JSON following the figures and from the fragment builders.
//! Reference counts come from the chapter text and from Grübler's mobility count.

use bondmech::bond::causality::{assign_causality, CausalityReport, Stage, StorageCausality};
use bondmech::bond::fragments::{
    decoupled_revolute, force, pin_to_ground, planar_body_fixed_frame, planar_body_translating,
    point_mass, prismatic, revolute, rigid_body_3d, torque, Axis, PlanarBodySpec, RigidBody3Spec,
};
use bondmech::bond::json::RawBondGraph;
use bondmech::bond::model::{BondGraph, ElementKind, Parameter};
use serde_json::{json, Value};

fn report(g: &BondGraph) -> CausalityReport {
    assign_causality(g).expect("valid graph").report(g)
}

/// (integral, differential) inertias.
fn inertia_counts(g: &BondGraph, r: &CausalityReport) -> (usize, usize) {
    let mut counts = (0, 0);
    for s in &r.storages {
        let id = g.element_by_name(&s.element).unwrap();
        if g.element(id).kind == ElementKind::I {
            match s.causality {
                StorageCausality::Integral => counts.0 += 1,
                StorageCausality::Differential => counts.1 += 1,
            }
        }
    }
    counts
}

fn graph_from(v: Value) -> BondGraph {
    let raw: RawBondGraph = serde_json::from_value(v).expect("raw JSON");
    raw.to_graph().expect("valid graph")
}

fn bar(name: &str, points: &[(&str, f64, f64)]) -> PlanarBodySpec {
    PlanarBodySpec {
        name: name.into(),
        mass: 1.0,
        inertia: 1.0 / 12.0,
        gravity: 9.81,
        points: points
            .iter()
            .map(|(n, x, y)| (n.to_string(), *x, *y))
            .collect(),
        rotation: true,
    }
}

// ---------------------------------------------------------------- 16.1 rigid body (EJS)

fn ejs_json() -> Value {
    let mut elements = vec![];
    let mut bonds = vec![];
    for (j, i, m) in [
        ("vx", "Imx", 2.0),
        ("vy", "Imy", 2.0),
        ("vz", "Imz", 2.0),
        ("wx", "IJx", 1.0),
        ("wy", "IJy", 2.0),
        ("wz", "IJz", 3.0),
    ] {
        elements.push(json!({"name": j, "kind": "1"}));
        elements.push(json!({"name": i, "kind": "I", "value": m}));
        elements.push(json!({"name": format!("S{j}"), "kind": "Se", "value": 0.0}));
        bonds.push(json!({"from": j, "to": i}));
        bonds.push(json!({"from": format!("S{j}"), "to": j}));
    }
    // Fig. 2: translational triangle modulated by m·ω, rotational by h
    for (name, from, to, modulus) in [
        ("g_xy", "vy", "vx", "2*p_IJz/3"),
        ("g_yz", "vz", "vy", "2*p_IJx/1"),
        ("g_zx", "vx", "vz", "2*p_IJy/2"),
        ("h_x", "wy", "wz", "p_IJx"),
        ("h_y", "wz", "wx", "p_IJy"),
        ("h_z", "wx", "wy", "p_IJz"),
    ] {
        elements.push(json!({"name": name, "kind": "MGY", "modulus": modulus}));
        bonds.push(json!({"from": from, "to": name}));
        bonds.push(json!({"from": name, "to": to}));
    }
    json!({"elements": elements, "bonds": bonds})
}

#[test]
fn rigid_body_ejs_from_json_has_six_integral_inertias() {
    let g = graph_from(ejs_json());
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (6, 0));
    assert_eq!(r.dof, 6);
    assert!(r.conflicts.is_empty(), "{:?}", r.conflicts);
}

#[test]
fn rigid_body_ejs_fragment_has_six_integral_inertias_with_body_and_inertial_ports() {
    let mut g = BondGraph::new();
    let b = rigid_body_3d(
        &mut g,
        &RigidBody3Spec {
            name: "sat".into(),
            mass: 10.0,
            inertia: [1.0, 2.0, 3.0],
            rotation: None,
        },
    );
    for k in 0..3 {
        torque(&mut g, &format!("tau{k}"), b.w[k], Parameter::Const(0.0));
    }
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (6, 0));
    assert_eq!(r.dof, 6);

    let mut g = BondGraph::new();
    let rot: [[String; 3]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|k| format!("R{}{}", i + 1, k + 1)));
    for row in &rot {
        for e in row {
            g.add_signal(e.clone());
        }
    }
    let b = rigid_body_3d(
        &mut g,
        &RigidBody3Spec {
            name: "sat".into(),
            mass: 10.0,
            inertia: [1.0, 2.0, 3.0],
            rotation: Some(rot),
        },
    );
    for (k, &p) in b.force_ports.unwrap().iter().enumerate() {
        let e = g.add_element(
            format!("F{k}"),
            ElementKind::Se,
            Some(Parameter::Expr("sin(t)".into())),
        );
        g.add_bond(e, p);
    }
    for (k, &p) in b.torque_ports.unwrap().iter().enumerate() {
        let e = g.add_element(
            format!("T{k}"),
            ElementKind::Se,
            Some(Parameter::Const(0.0)),
        );
        g.add_bond(e, p);
    }
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (6, 0));
    assert_eq!(r.dof, 6);
    assert!(r.conflicts.is_empty(), "{:?}", r.conflicts);
}

// ---------------------------------------------------------------- 16.5 two hinged bars (Fig. 16)

/// One bar in the translating frame (Fig. 24) with its points; Sf-free points are 0-junctions
/// `s<P><axis>` summing V_O and the MTF term (the point's own 1-junction is a pure identity).
fn bar_json(
    elements: &mut Vec<Value>,
    bonds: &mut Vec<Value>,
    b: &str,
    points: &[(&str, &str, &str)],
) {
    for (j, i) in [("vx", "mx"), ("vy", "my"), ("w", "J")] {
        elements.push(json!({"name": format!("{b}{j}"), "kind": "1"}));
        elements.push(json!({"name": format!("{b}{i}"), "kind": "I", "value": 1.0}));
        bonds.push(json!({"from": format!("{b}{j}"), "to": format!("{b}{i}")}));
    }
    elements.push(json!({"name": format!("{b}W"), "kind": "Se", "value": -9.81}));
    bonds.push(json!({"from": format!("{b}W"), "to": format!("{b}vy")}));
    for (p, mx, my) in points {
        for (axis, modulus) in [("x", mx), ("y", my)] {
            let s = format!("{b}s{p}{axis}");
            let m = format!("{b}m{p}{axis}");
            elements.push(json!({"name": s, "kind": "0"}));
            elements.push(json!({"name": m, "kind": "MTF", "modulus": modulus}));
            bonds.push(json!({"from": format!("{b}v{axis}"), "to": s}));
            bonds.push(json!({"from": format!("{b}w"), "to": m}));
            bonds.push(json!({"from": m, "to": s}));
        }
    }
}

fn hinged_bars_json(pinned: bool) -> Value {
    let (mut e, mut b) = (vec![], vec![]);
    let mut p1 = vec![("A", "-0.5*sin(x_1w)", "0.5*cos(x_1w)")];
    if pinned {
        p1.push(("O", "0.5*sin(x_1w)", "-0.5*cos(x_1w)"));
    }
    bar_json(&mut e, &mut b, "1", &p1);
    bar_json(
        &mut e,
        &mut b,
        "2",
        &[("A", "0.5*sin(x_2w)", "-0.5*cos(x_2w)")],
    );
    // Fig. 16: a 1-junction per axis equating V_A seen from both bars (both point bonds point
    // into it: each bar's 0-junction passes its V_A out, and the pin forces are opposite)
    for axis in ["x", "y"] {
        let j = format!("A{axis}");
        e.push(json!({"name": j, "kind": "1"}));
        b.push(json!({"from": format!("1sA{axis}"), "to": j}));
        b.push(json!({"from": format!("2sA{axis}"), "to": j}));
        if pinned {
            // 16.7: the pin to ground is a zero flow source on V_O
            let sf = format!("O{axis}");
            e.push(json!({"name": sf, "kind": "Sf", "value": 0.0}));
            b.push(json!({"from": sf, "to": format!("1sO{axis}")}));
        }
    }
    json!({"elements": e, "bonds": b})
}

#[test]
fn two_hinged_bars_from_json_have_four_integral_two_differential() {
    let g = graph_from(hinged_bars_json(false));
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (4, 2));
    assert_eq!(r.dof, 4);
    assert!(r.conflicts.is_empty(), "{:?}", r.conflicts);
    // Causality by matching (issue 13), at the graph's state (both bars horizontal, x = 0):
    // the knee's rows V_A1 = V_A2 hold bar 2's translations with coefficient 1 and its
    // rotation with ½·sin 0 = 0 (x row) and ½ (y row); each row pivots on the unit entry, so
    // bar 2's translations are differential and both rotations integral (the old SCAP made
    // 2J differential through the x row, dividing by sin 0). Bar 1 stays integral: ties between
    // the bars go to the later name, not to the file order. Each differential inertia is forced
    // at its point-A sum by the MTF term and the pin junction.
    assert_forcing_is_named(&g, &r);
    // (element, junction, via elements, path, via bonds)
    type Forced<'a> = (&'a str, &'a str, Vec<&'a str>, Vec<&'a str>, Vec<&'a str>);
    let forced: Vec<Forced> = r
        .differential
        .iter()
        .map(|d| {
            (
                d.element.as_str(),
                d.forced_by_junction.as_str(),
                d.via_elements.iter().map(|s| s.as_str()).collect(),
                d.path.iter().map(|s| s.as_str()).collect(),
                d.via_bonds.iter().map(|s| s.as_str()).collect(),
            )
        })
        .collect();
    let bond = |from: &str, to: &str| {
        let (f, t) = (g.element_by_name(from), g.element_by_name(to));
        let b = g
            .bonds
            .iter()
            .find(|b| Some(b.from) == f && Some(b.to) == t);
        b.unwrap().name.clone()
    };
    let (b_mx, b_ax) = (bond("2mAx", "2sAx"), bond("2sAx", "Ax"));
    let (b_my, b_ay) = (bond("2mAy", "2sAy"), bond("2sAy", "Ay"));
    assert_eq!(
        forced,
        vec![
            (
                "2mx",
                "2sAx",
                vec!["2mAx", "Ax"],
                vec!["2vx", "2sAx"],
                vec![b_mx.as_str(), b_ax.as_str()]
            ),
            (
                "2my",
                "2sAy",
                vec!["2mAy", "Ay"],
                vec!["2vy", "2sAy"],
                vec![b_my.as_str(), b_ay.as_str()]
            ),
        ]
    );
}

/// Every differential storage names a junction (or source) with the bonds at it that forced it.
fn assert_forcing_is_named(g: &BondGraph, r: &CausalityReport) {
    for d in &r.differential {
        let at = g
            .element_by_name(&d.forced_by_junction)
            .unwrap_or_else(|| panic!("{d:?}"));
        assert!(
            matches!(
                g.element(at).kind,
                ElementKind::Zero | ElementKind::One | ElementKind::Sf | ElementKind::Se
            ),
            "{d:?}"
        );
        assert!(!d.via_bonds.is_empty(), "{d:?}");
        assert_eq!(d.via_bonds.len(), d.via_elements.len());
        for (b, other) in d.via_bonds.iter().zip(&d.via_elements) {
            let bond = g.bonds.iter().find(|x| &x.name == b).unwrap();
            let ends = [
                g.element(bond.from).name.as_str(),
                g.element(bond.to).name.as_str(),
            ];
            assert!(ends.contains(&d.forced_by_junction.as_str()), "{d:?}");
            assert!(ends.contains(&other.as_str()), "{d:?}");
        }
    }
}

/// Differential storages whose causality the look-ahead chose (not local propagation).
fn decided_by_look_ahead(r: &CausalityReport) -> usize {
    r.differential
        .iter()
        .filter(|d| {
            r.bond_causality
                .iter()
                .any(|b| b.bond == d.bond && b.stage == Stage::Storage)
        })
        .count()
}

#[test]
fn two_hinged_bars_fragment_have_four_integral_two_differential() {
    let mut g = BondGraph::new();
    let b1 = planar_body_translating(&mut g, &bar("bar1", &[("A", 0.5, 0.0)]));
    let b2 = planar_body_translating(&mut g, &bar("bar2", &[("A", -0.5, 0.0), ("B", 0.5, 0.0)]));
    revolute(
        &mut g,
        "knee",
        b1.point("A").unwrap(),
        b2.point("A").unwrap(),
    );
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (4, 2));
    assert_eq!(r.dof, 4);
    assert!(r.conflicts.is_empty(), "{:?}", r.conflicts);
    assert!(
        r.differential
            .iter()
            .all(|d| d.element.starts_with("bar2.")),
        "{:?}",
        r.differential
    );
}

// ---------------------------------------------------------------- 16.6 decoupled bars (Fig. 18)

#[test]
fn decoupled_hinged_bars_have_six_integral_inertias_and_two_spring_states() {
    let mut g = BondGraph::new();
    let b1 = planar_body_translating(&mut g, &bar("bar1", &[("A", 0.5, 0.0)]));
    let b2 = planar_body_translating(&mut g, &bar("bar2", &[("A", -0.5, 0.0)]));
    decoupled_revolute(
        &mut g,
        "knee",
        b1.point("A").unwrap(),
        Some(b2.point("A").unwrap()),
        1e8,
        None,
    );
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (6, 0));
    // seed 16.6: six degrees of freedom; the two spring displacements are states, not DOF
    assert_eq!((r.dof, r.state_count, r.states.len()), (6, 8, 8));
    assert!(r.states.contains(&"knee.x.k".to_string()));
}

// ---------------------------------------------------------------- 16.7 double pendulum (Fig. 20, 21)

#[test]
fn double_pendulum_from_json_has_two_integral_four_differential() {
    let g = graph_from(hinged_bars_json(true));
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (2, 4));
    assert_eq!(r.dof, 2);
    assert!(r.conflicts.is_empty(), "{:?}", r.conflicts);
}

fn double_pendulum(decoupled: bool) -> BondGraph {
    let mut g = BondGraph::new();
    let b1 = planar_body_translating(&mut g, &bar("bar1", &[("O", -0.5, 0.0), ("A", 0.5, 0.0)]));
    let b2 = planar_body_translating(&mut g, &bar("bar2", &[("A", -0.5, 0.0), ("B", 0.5, 0.0)]));
    let (o, a1, a2) = (
        b1.point("O").unwrap(),
        b1.point("A").unwrap(),
        b2.point("A").unwrap(),
    );
    if decoupled {
        decoupled_revolute(&mut g, "hip", o, None, 1e6, Some(10.0));
        decoupled_revolute(&mut g, "knee", a1, Some(a2), 1e6, Some(10.0));
    } else {
        pin_to_ground(&mut g, "hip", o, true);
        revolute(&mut g, "knee", a1, a2);
    }
    g
}

#[test]
fn double_pendulum_fragment_has_two_integral_four_differential() {
    let g = double_pendulum(false);
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (2, 4));
    assert_eq!(r.dof, 2);
    assert!(r.conflicts.is_empty(), "{:?}", r.conflicts);
    assert!(r.algebraic_loops.is_empty());
}

#[test]
fn decoupled_double_pendulum_has_six_integral_inertias() {
    let g = double_pendulum(true);
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (6, 0));
    // seed 16.7 (Fig. 21): "seis grados de libertad"; the states are the 6 momenta + 4 spring
    // displacements (four springs replace four constraints)
    assert_eq!(r.dof, 6);
    assert_eq!(r.state_count, 10);
    assert!(r.conflicts.is_empty(), "{:?}", r.conflicts);
}

// ---------------------------------------------------------------- 16.3 body-fixed frame

#[test]
fn body_fixed_free_bar_has_three_states_and_pinned_bar_one() {
    let mut g = BondGraph::new();
    planar_body_fixed_frame(&mut g, &bar("bar", &[("O", -0.5, 0.0), ("A", 0.5, 0.0)]));
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (3, 0));

    // a bar pinned at one end: 3 − 2 = 1 degree of freedom
    let mut g = BondGraph::new();
    let b = planar_body_fixed_frame(&mut g, &bar("bar", &[("O", -0.5, 0.0)]));
    pin_to_ground(&mut g, "pin", b.point("O").unwrap(), true);
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (1, 2));
}

// ---------------------------------------------------------------- 16.8 slider-crank (Fig. 29)

#[test]
fn slider_crank_has_one_degree_of_freedom() {
    // Grübler: 3 + 3 + 2 coordinates − 2·3 (revolutes O, A, B) − 1 (cylinder) = 1
    let mut g = BondGraph::new();
    let crank = planar_body_translating(&mut g, &bar("crank", &[("O", 0.0, 0.0), ("A", 0.1, 0.0)]));
    let rod = planar_body_translating(&mut g, &bar("rod", &[("A", -0.15, 0.0), ("B", 0.15, 0.0)]));
    let piston = point_mass(&mut g, "piston", 0.5, 9.81);
    pin_to_ground(&mut g, "O", crank.point("O").unwrap(), true);
    revolute(
        &mut g,
        "A",
        crank.point("A").unwrap(),
        rod.point("A").unwrap(),
    );
    revolute(&mut g, "B", rod.point("B").unwrap(), &piston);
    prismatic(&mut g, "cyl", (&piston, None), None, Axis::Y);
    force(
        &mut g,
        "Eg",
        &piston,
        Axis::Y,
        Parameter::Expr("100*sin(t)".into()),
    );
    let r = report(&g);
    let (integral, differential) = inertia_counts(&g, &r);
    assert_eq!((integral, differential), (1, 7));
    assert!(r.conflicts.is_empty(), "{:?}", r.conflicts);
    assert_forcing_is_named(&g, &r);
    // the cylinder (Sf = 0 across the axis) is what fixes the piston's x velocity
    let px = r
        .differential
        .iter()
        .find(|d| d.element == "piston.I_m_x")
        .unwrap();
    assert_eq!(px.via_elements, vec!["cyl.x"], "{px:?}");
}

// ---------------------------------------------------------------- small reference systems

#[test]
fn mass_spring_damper_has_two_states_and_one_degree_of_freedom() {
    let g = graph_from(json!({
        "elements": [
            {"name": "F", "kind": "Se", "value": "sin(t)"},
            {"name": "v", "kind": "1"},
            {"name": "m", "kind": "I", "value": 1.0},
            {"name": "k", "kind": "C", "stiffness": 100.0},
            {"name": "c", "kind": "R", "value": 0.5}
        ],
        "bonds": [{"from": "F", "to": "v"}, {"from": "v", "to": "m"},
                  {"from": "v", "to": "k"}, {"from": "v", "to": "c"}]
    }));
    let r = report(&g);
    assert_eq!((r.dof, r.state_count), (1, 2));
    assert_eq!(r.state_variables, vec!["p_m", "q_k"]);
    assert!(r.differential.is_empty() && r.conflicts.is_empty() && r.algebraic_loops.is_empty());
}

#[test]
fn two_flow_sources_on_a_one_junction_conflict_naming_both() {
    let g = graph_from(json!({
        "elements": [
            {"name": "Sf1", "kind": "Sf", "value": 1.0},
            {"name": "Sf2", "kind": "Sf", "value": 2.0},
            {"name": "j", "kind": "1"},
            {"name": "r", "kind": "R", "value": 1.0}
        ],
        "bonds": [{"from": "Sf1", "to": "j"}, {"from": "Sf2", "to": "j"}, {"from": "j", "to": "r"}]
    }));
    let r = report(&g);
    assert_eq!(r.conflicts.len(), 1, "{:?}", r.conflicts);
    assert_eq!(r.conflicts[0].junction, "j");
    assert_eq!(r.conflicts[0].elements, vec!["Sf1", "Sf2"]);
    // the assignment still completes
    assert_eq!(r.bond_causality.len(), 3);
}

#[test]
fn two_effort_sources_on_a_zero_junction_conflict_naming_both() {
    let g = graph_from(json!({
        "elements": [
            {"name": "E1", "kind": "Se", "value": 1.0},
            {"name": "E2", "kind": "Se", "value": 2.0},
            {"name": "j", "kind": "0"},
            {"name": "k", "kind": "C", "compliance": 0.1}
        ],
        "bonds": [{"from": "E1", "to": "j"}, {"from": "E2", "to": "j"}, {"from": "j", "to": "k"}]
    }));
    let r = report(&g);
    assert_eq!(r.conflicts.len(), 1);
    assert_eq!(r.conflicts[0].elements, vec!["E1", "E2"]);
    // the capacitor on an effort-imposed 0-junction is differential
    assert_eq!(r.differential.len(), 1);
    assert_eq!(r.differential[0].element, "k");
}

#[test]
fn resistor_resistor_loop_is_reported_as_algebraic() {
    // Se → 1(R1) → 0(R2) → 1(I): v_A = v_I + F/R2 and F = Se − R1·v_A is implicit in v_A
    let g = graph_from(json!({
        "elements": [
            {"name": "Se", "kind": "Se", "value": 1.0},
            {"name": "jA", "kind": "1"},
            {"name": "R1", "kind": "R", "value": 2.0},
            {"name": "jB", "kind": "0"},
            {"name": "R2", "kind": "R", "value": 3.0},
            {"name": "jC", "kind": "1"},
            {"name": "m", "kind": "I", "value": 1.0}
        ],
        "bonds": [{"from": "Se", "to": "jA"}, {"from": "jA", "to": "R1"}, {"from": "jA", "to": "jB"},
                  {"from": "jB", "to": "R2"}, {"from": "jB", "to": "jC"}, {"from": "jC", "to": "m"}]
    }));
    let r = report(&g);
    assert_eq!(
        r.algebraic_loops,
        vec![vec!["R1".to_string(), "R2".to_string()]]
    );
    assert_eq!(r.dof, 1);
    let text = serde_json::to_value(&r).unwrap();
    for key in [
        "dof",
        "state_count",
        "states",
        "differential",
        "conflicts",
        "algebraic_loops",
    ] {
        assert!(text.get(key).is_some(), "missing {key}");
    }
}

#[test]
fn causality_is_deterministic() {
    let a = report(&double_pendulum(false));
    let b = report(&double_pendulum(false));
    assert_eq!(a, b);
}

// ---------------------------------------------------------------- 16.4–16.5 body-fixed frames

fn body_fixed_pair(pinned: bool) -> BondGraph {
    use bondmech::bond::fragments::change_frame;
    let mut g = BondGraph::new();
    let b1 = planar_body_fixed_frame(&mut g, &bar("bar1", &[("O", -0.5, 0.0), ("A", 0.5, 0.0)]));
    let b2 = planar_body_fixed_frame(&mut g, &bar("bar2", &[("A", -0.5, 0.0)]));
    // Fig. 10: V_A of bar 1 expressed in the axes of bar 2, then Fig. 16's equating 1-junctions
    let a_in_2 = change_frame(
        &mut g,
        "knee.frame",
        b1.point("A").unwrap(),
        "x_bar2.omega - x_bar1.omega",
    );
    revolute(&mut g, "knee", &a_in_2, b2.point("A").unwrap());
    if pinned {
        pin_to_ground(&mut g, "hip", b1.point("O").unwrap(), true);
    }
    g
}

#[test]
fn body_fixed_hinged_bars_have_four_integral_two_differential() {
    let g = body_fixed_pair(false);
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (4, 2));
    assert!(r.conflicts.is_empty(), "{:?}", r.conflicts);
}

#[test]
fn body_fixed_double_pendulum_has_two_integral_four_differential() {
    let g = body_fixed_pair(true);
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (2, 4));
    assert!(r.conflicts.is_empty(), "{:?}", r.conflicts);
}

// ---------------------------------------------------------------- N-link chains

fn n_link_pendulum(n: usize, decoupled: bool) -> BondGraph {
    let mut g = BondGraph::new();
    let mut prev: Option<bondmech::bond::fragments::PointJunctions> = None;
    for i in 0..n {
        let b = planar_body_translating(
            &mut g,
            &bar(&format!("l{i}"), &[("O", -0.5, 0.0), ("A", 0.5, 0.0)]),
        );
        let o = b.point("O").unwrap().clone();
        let name = format!("j{i}");
        match (&prev, decoupled) {
            (None, false) => pin_to_ground(&mut g, &name, &o, true),
            (None, true) => decoupled_revolute(&mut g, &name, &o, None, 1e6, None),
            (Some(p), false) => revolute(&mut g, &name, p, &o),
            (Some(p), true) => decoupled_revolute(&mut g, &name, p, Some(&o), 1e6, None),
        }
        prev = Some(b.point("A").unwrap().clone());
    }
    g
}

#[test]
fn n_link_pendulum_has_n_integral_and_2n_differential_inertias() {
    // Grübler: 3N coordinates − 2N pin constraints = N
    for n in [1, 2, 3, 4, 17] {
        let g = n_link_pendulum(n, false);
        let r = report(&g);
        assert_eq!(inertia_counts(&g, &r), (n, 2 * n), "N = {n}");
        assert!(r.conflicts.is_empty(), "N = {n}: {:?}", r.conflicts);
        let g = n_link_pendulum(n, true);
        let r = report(&g);
        assert_eq!(inertia_counts(&g, &r), (3 * n, 0), "decoupled N = {n}");
        assert_eq!((r.dof, r.state_count), (3 * n, 3 * n + 2 * n));
    }
}

#[test]
fn long_chain_causality_is_fast() {
    let g = n_link_pendulum(200, false);
    let start = std::time::Instant::now();
    let r = report(&g);
    let elapsed = start.elapsed();
    assert_eq!(inertia_counts(&g, &r), (200, 400));
    println!(
        "200-link chain: {} elements, {} bonds, causality in {elapsed:?}",
        g.elements.len(),
        g.bonds.len()
    );
    assert!(elapsed.as_secs_f64() < 5.0, "{elapsed:?}");
}

#[test]
fn four_bar_linkage_has_one_degree_of_freedom() {
    // Grübler: 3·3 coordinates − 2·4 pin constraints = 1 (a closed kinematic loop)
    let mut g = BondGraph::new();
    let crank =
        planar_body_translating(&mut g, &bar("crank", &[("O", -0.5, 0.0), ("A", 0.5, 0.0)]));
    let coupler = planar_body_translating(
        &mut g,
        &bar("coupler", &[("A", -1.0, 0.0), ("B", 1.0, 0.0)]),
    );
    let rocker = planar_body_translating(
        &mut g,
        &bar("rocker", &[("B", -0.75, 0.0), ("D", 0.75, 0.0)]),
    );
    pin_to_ground(&mut g, "O", crank.point("O").unwrap(), true);
    revolute(
        &mut g,
        "A",
        crank.point("A").unwrap(),
        coupler.point("A").unwrap(),
    );
    revolute(
        &mut g,
        "B",
        coupler.point("B").unwrap(),
        rocker.point("B").unwrap(),
    );
    pin_to_ground(&mut g, "D", rocker.point("D").unwrap(), true);
    let r = report(&g);
    assert_eq!(inertia_counts(&g, &r), (1, 8));
    assert!(r.conflicts.is_empty(), "{:?}", r.conflicts);
    // the closed loop is found by the look-ahead, which must still name junction and bonds
    assert!(decided_by_look_ahead(&r) > 0, "{:?}", r.differential);
    assert_forcing_is_named(&g, &r);
}
