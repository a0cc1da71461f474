//! No code: see `Cargo.toml`. Its dependencies give the crates that are built alone (xtask and the
//! Python extension) the features `cargo test --workspace` turns on, so they reuse its build.
