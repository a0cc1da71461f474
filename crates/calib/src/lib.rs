//! The library half of `calib`: the command flows that the binary's subcommands and the Python
//! package (`crates/python`) both run, so that the two give the same numbers by construction.
//! The binary (`main.rs`) parses the command line and prints; this half knows no flags.

pub mod flow;
