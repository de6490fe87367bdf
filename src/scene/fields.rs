//! The fields of one JSON object of a scene, read with their paths: the object's keys checked
//! for duplicates and unknown names, and the values read as numbers, strings, vectors. Shared
//! by the scene's reader ([`super::parse`]) and the joint kinds' own fields
//! ([`super::joint_kind`]).

use super::error::{field, index, Problems};
use super::tree::Json;

/// Keys allowed in every object.
const COMMENT: &str = "comment";

/// The keys of one JSON object, checked for duplicates and unknown names.
pub(crate) struct Fields<'a> {
    path: String,
    entries: &'a [(String, Json)],
}

impl<'a> Fields<'a> {
    /// Reads `j` as an object whose keys must be among `allowed` (plus `"comment"`).
    pub(crate) fn new(
        p: &mut Problems,
        path: &str,
        j: &'a Json,
        allowed: &[&str],
    ) -> Option<Fields<'a>> {
        let Json::Object(entries) = j else {
            p.push(path, format!("expected an object, got {}", j.kind()));
            return None;
        };
        let mut seen = std::collections::HashSet::with_capacity(entries.len());
        for (k, _) in entries.iter() {
            let kp = field(path, k);
            if !seen.insert(k.as_str()) {
                p.push(kp, "duplicate key");
            } else if k != COMMENT && !allowed.contains(&k.as_str()) {
                p.push(kp, unknown_field(k, allowed));
            }
        }
        Some(Fields {
            path: path.to_string(),
            entries,
        })
    }

    pub(crate) fn get(&self, key: &str) -> Option<&'a Json> {
        self.entries.iter().find(|(k, _)| k == key).map(|(_, v)| v)
    }

    pub(crate) fn path(&self, key: &str) -> String {
        field(&self.path, key)
    }

    pub(crate) fn required(&self, p: &mut Problems, key: &str) -> Option<&'a Json> {
        let v = self.get(key);
        if v.is_none() {
            p.push(self.path(key), "required field is missing");
        }
        v
    }

    pub(crate) fn number(&self, p: &mut Problems, key: &str) -> Option<f64> {
        self.get(key).and_then(|j| number(p, &self.path(key), j))
    }

    pub(crate) fn required_number(&self, p: &mut Problems, key: &str) -> Option<f64> {
        self.required(p, key)
            .and_then(|j| number(p, &self.path(key), j))
    }

    pub(crate) fn string(&self, p: &mut Problems, key: &str) -> Option<String> {
        self.get(key).and_then(|j| string(p, &self.path(key), j))
    }

    pub(crate) fn boolean(&self, p: &mut Problems, key: &str) -> Option<bool> {
        match self.get(key)? {
            Json::Bool(b) => Some(*b),
            j => {
                p.push(
                    self.path(key),
                    format!("expected a boolean, got {}", j.kind()),
                );
                None
            }
        }
    }

    pub(crate) fn vector(&self, p: &mut Problems, key: &str) -> Option<Vec<f64>> {
        self.get(key).and_then(|j| vector(p, &self.path(key), j))
    }

    pub(crate) fn array(&self, p: &mut Problems, key: &str) -> &'a [Json] {
        match self.get(key) {
            None => &[],
            Some(Json::Array(a)) => a,
            Some(j) => {
                p.push(
                    self.path(key),
                    format!("expected an array, got {}", j.kind()),
                );
                &[]
            }
        }
    }
}

pub(crate) fn number(p: &mut Problems, path: &str, j: &Json) -> Option<f64> {
    match j {
        Json::Number(x) if x.is_subnormal() => {
            // kept for the field's own check (a mass's range), which speaks first
            p.deferred.push(super::error::Problem::new(
                path,
                format!("{x:e} is a subnormal number (nonzero, below 2.2e-308, where doubles lose their digits): no quantity of a scene is that small; write 0 if 0 is meant"),
            ));
            Some(*x)
        }
        Json::Number(x) => Some(*x),
        _ => {
            p.push(path, format!("expected a number, got {}", j.kind()));
            None
        }
    }
}

pub(crate) fn string(p: &mut Problems, path: &str, j: &Json) -> Option<String> {
    match j {
        Json::String(s) => Some(s.clone()),
        _ => {
            p.push(path, format!("expected a string, got {}", j.kind()));
            None
        }
    }
}

pub(crate) fn vector(p: &mut Problems, path: &str, j: &Json) -> Option<Vec<f64>> {
    let Json::Array(items) = j else {
        p.push(
            path,
            format!("expected an array of numbers, got {}", j.kind()),
        );
        return None;
    };
    let mut out = Vec::with_capacity(items.len());
    let mut ok = true;
    for (i, item) in items.iter().enumerate() {
        match number(p, &index(path, i), item) {
            Some(x) => out.push(x),
            None => ok = false,
        }
    }
    ok.then_some(out)
}

/// The candidate closest to `name` when it is within the edit distance [`unknown_field`]
/// allows (a third of the longer name, at least 1, 2 from 5 letters), compared as written and
/// then in lower case: what a "did you mean" names for a mistyped joint, output or column.
pub(crate) fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let lower = name.trim().to_lowercase();
    candidates
        .into_iter()
        .filter(|c| *c != name)
        .map(|c| {
            let d = crate::bond::json::edit_distance(name, c)
                .min(crate::bond::json::edit_distance(&lower, &c.to_lowercase()));
            (d, c)
        })
        .min()
        .filter(|(d, c)| {
            let longer = c.len().max(name.len());
            *d <= (longer / 3).max(if longer >= 5 { 2 } else { 1 })
        })
        .map(|(_, c)| c)
}

/// `" (did you mean 'x'?)"` for [`did_you_mean`], or nothing.
pub(crate) fn did_you_mean_note<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> String {
    did_you_mean(name, candidates).map_or_else(String::new, |c| format!(" (did you mean '{c}'?)"))
}

/// `unknown field (did you mean "gravity"? expected one of: …)`: the closest allowed key when
/// one is within an edit distance of a third of the longer name (at least 1, 2 from 5
/// letters), compared in lower case with `-` and spaces read as `_`.
fn unknown_field(key: &str, allowed: &[&str]) -> String {
    let norm: String = key
        .trim()
        .to_lowercase()
        .chars()
        .map(|c| if c == '-' || c == ' ' { '_' } else { c })
        .collect();
    let best = allowed
        .iter()
        .map(|k| (crate::bond::json::edit_distance(&norm, k), *k))
        .min()
        .filter(|(d, k)| {
            let longer = k.len().max(norm.len());
            *d <= (longer / 3).max(if longer >= 5 { 2 } else { 1 })
        })
        .map(|(_, k)| k);
    match best {
        Some(b) => format!(
            "unknown field (did you mean \"{b}\"? expected one of: {})",
            allowed.join(", ")
        ),
        None => format!("unknown field (expected one of: {})", allowed.join(", ")),
    }
}
