//! Build script: insist on a system SUNDIALS 6.x install.
//!
//! `sundials-sys` silently falls back to building its vendored SUNDIALS 7.x with
//! cmake when bindgen cannot read the system headers; bondmech is written against
//! the 6.x API (see `vendor-notes/sundials.md`).
//!
//! `sundials-sys` declares `links = "sundials"`, so cargo runs *its* build script
//! before this one: by the time we run, a vendored build has already happened.
//! The guards that act *before* it are `scripts/check-deps.sh` (run by
//! `scripts/install-deps.sh`) and the `[env] CMAKE` stand-in in
//! `.cargo/config.toml`. Here we check the result:
//! 1. `DEP_SUNDIALS_ROOT` is set exactly when sundials-sys ran cmake (the `cmake`
//!    crate prints `cargo:root=...`, which cargo forwards to dependents of a
//!    `links` package as `DEP_SUNDIALS_ROOT`): fail if it is set;
//! 2. the system headers exist and declare `SUNDIALS_VERSION_MAJOR 6`.
//!
//! `src/sundials/version.rs` adds a compile-time assertion that the bindings
//! sundials-sys generated declare the same version as these headers.
//! (No libclang check here: if we run at all, sundials-sys's bindgen found it.)

use std::env;
use std::fs;
use std::path::{Path, PathBuf};

const INSTALL_HINT: &str = "apt-get install libsundials-dev libclang-dev pkg-config";
const REQUIRED_HEADERS: [&str; 3] = [
    "idas/idas.h",
    "cvodes/cvodes.h",
    "sundials/sundials_config.h",
];

fn candidate_dirs() -> Vec<PathBuf> {
    match env::var_os("SUNDIALS_INCLUDE_DIR") {
        Some(dir) => vec![PathBuf::from(dir)],
        None => vec![
            PathBuf::from("/usr/include"),
            PathBuf::from("/usr/local/include"),
        ],
    }
}

fn has_all_headers(dir: &Path) -> bool {
    REQUIRED_HEADERS.iter().all(|h| dir.join(h).is_file())
}

/// Value of `#define NAME value` in the config header, quotes stripped.
fn define_value(config: &str, name: &str) -> Option<String> {
    config.lines().find_map(|line| {
        let mut parts = line.split_whitespace();
        if parts.next()? != "#define" || parts.next()? != name {
            return None;
        }
        Some(parts.next()?.trim_matches('"').to_string())
    })
}

fn main() {
    println!("cargo:rerun-if-env-changed=SUNDIALS_INCLUDE_DIR");
    println!("cargo:rerun-if-env-changed=SUNDIALS_LIBRARY_DIR");
    println!("cargo:rerun-if-changed=build.rs");
    // resolve the shared libraries' symbols (SUNDIALS, libm) when the CLI starts, not at
    // their first call inside a timed solve (`cpu_seconds` of a short run paid the lazy
    // binding); also the hardening Debian builds use
    println!("cargo:rustc-link-arg-bins=-Wl,-z,now");
    bundled_scenes();

    if let Some(root) = env::var_os("DEP_SUNDIALS_ROOT") {
        panic!(
            "sundials-sys built its vendored SUNDIALS with cmake (installed in {}), which means \
             bindgen could not use the system SUNDIALS 6.x headers; bondmech refuses it.\n\
             Install the system packages with:\n    {INSTALL_HINT}\n\
             or point SUNDIALS_INCLUDE_DIR / SUNDIALS_LIBRARY_DIR at a SUNDIALS 6.x install.",
            PathBuf::from(root).display()
        );
    }

    // SUNDIALS' KLU solver (`SUNLinSol_KLU`, src/sundials/sparse.rs): Debian's libsundials-dev
    // ships it as its own library, which sundials-sys links only with its `klu` feature (and
    // that feature builds SUNDIALS from source). The search path is sundials-sys's.
    if let Some(dir) = env::var_os("SUNDIALS_LIBRARY_DIR") {
        println!(
            "cargo:rustc-link-search=native={}",
            PathBuf::from(dir).display()
        );
    }
    println!("cargo:rustc-link-lib=dylib=sundials_sunlinsolklu");

    let dirs = candidate_dirs();
    let Some(dir) = dirs.iter().find(|d| has_all_headers(d)) else {
        let searched: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
        panic!(
            "bondmech needs the system SUNDIALS 6.x headers ({}) but did not find them in [{}].\n\
             Install them with:\n    {INSTALL_HINT}\n\
             or point SUNDIALS_INCLUDE_DIR / SUNDIALS_LIBRARY_DIR at another SUNDIALS 6.x install.",
            REQUIRED_HEADERS.join(", "),
            searched.join(", ")
        );
    };
    let config_path = dir.join("sundials/sundials_config.h");
    println!("cargo:rerun-if-changed={}", config_path.display());
    let config = fs::read_to_string(&config_path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", config_path.display()));
    let major = define_value(&config, "SUNDIALS_VERSION_MAJOR");
    let version = define_value(&config, "SUNDIALS_VERSION");
    match (major.as_deref(), version) {
        (Some("6"), Some(version)) => {
            println!("cargo:rustc-env=BONDMECH_SUNDIALS_HEADER_VERSION={version}");
        }
        (major, _) => panic!(
            "bondmech supports SUNDIALS 6.x only, but {} declares SUNDIALS_VERSION_MAJOR = {}.\n\
             Install the 6.x headers with:\n    {INSTALL_HINT}\n\
             or point SUNDIALS_INCLUDE_DIR / SUNDIALS_LIBRARY_DIR at a SUNDIALS 6.x install.",
            config_path.display(),
            major.unwrap_or("<missing>")
        ),
    }
}

/// `$OUT_DIR/bundled_scenes.rs`: every `scenes/*.json` as `(name, include_str!(file))`, sorted
/// by name, for the service's `GET /v1/scenes` (embedded: an installed binary has no
/// checkout to read them from).
fn bundled_scenes() {
    let dir = Path::new(&env::var("CARGO_MANIFEST_DIR").expect("cargo sets it")).join("scenes");
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut names: Vec<String> = fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let name = e.file_name().into_string().ok()?;
            name.strip_suffix(".json").map(str::to_string)
        })
        .collect();
    names.sort();
    let mut code = String::from("&[\n");
    for n in &names {
        let file = dir.join(format!("{n}.json"));
        code.push_str(&format!(
            "    ({n:?}, include_str!({:?})),\n",
            file.display().to_string()
        ));
    }
    code.push_str("]\n");
    let out = Path::new(&env::var("OUT_DIR").expect("cargo sets it")).join("bundled_scenes.rs");
    fs::write(&out, code).unwrap_or_else(|e| panic!("cannot write {}: {e}", out.display()));
}
