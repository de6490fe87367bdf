//! Generated benchmark scenes: the N-link pendulum of uniform bars.
//!
//! Bar `k` (1 kg, 1 m, inertia 1/12 kg·m², points `O = (−½, 0)`, `A = (+½, 0)`) lies along the
//! X axis with its centre at `x = k − ½`; bar 1's `O` is pinned to the ground at the origin,
//! bar `k`'s `O` to bar `k−1`'s `A`. All bars start horizontal at rest under gravity
//! (0, −9.81). For `N = 2` this is `scenes/double_pendulum.json`.

use crate::scene::{Scene, SceneError};

/// The JSON text of the N-link pendulum over `t_end` seconds, outputs every `output_step`.
pub fn n_link_pendulum_json(n: usize, t_end: f64, output_step: f64) -> String {
    let bodies: Vec<String> = (1..=n)
        .map(|k| {
            format!(
                r#"{{"name":"bar{k}","mass":1.0,"inertia":0.08333333333333333,"points":{{"O":[-0.5,0.0],"A":[0.5,0.0]}},"position":[{x},0.0],"angle":0.0}}"#,
                x = k as f64 - 0.5
            )
        })
        .collect();
    let joints: Vec<String> = (1..=n)
        .map(|k| {
            if k == 1 {
                r#"{"name":"pivot","type":"revolute","bodies":["ground","bar1"],"points":[[0.0,0.0],"O"]}"#.to_string()
            } else {
                format!(
                    r#"{{"name":"knee{k}","type":"revolute","bodies":["bar{p}","bar{k}"],"points":["A","O"]}}"#,
                    p = k - 1
                )
            }
        })
        .collect();
    format!(
        r#"{{"name":"n_link_{n}","dimension":2,"gravity":[0.0,-9.81],"bodies":[{}],"joints":[{}],"solve":{{"formulation":"dae","t_end":{t_end},"output_step":{output_step},"rtol":1e-8,"atol":1e-10}},"outputs":["energy","constraint_error"]}}"#,
        bodies.join(","),
        joints.join(",")
    )
}

/// The N-link pendulum as a [`Scene`] (see the module documentation).
pub fn n_link_pendulum(n: usize, t_end: f64, output_step: f64) -> Result<Scene, SceneError> {
    Scene::from_json_str(&n_link_pendulum_json(n, t_end, output_step))
}
