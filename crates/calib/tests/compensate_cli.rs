//! `calib compensate` end to end: the SPEC's CSV on stdout, a summary on stderr, refusals as one
//! line.

use std::path::{Path, PathBuf};
use std::process::Output;

mod common;
use common::{calib, fixture, text};

fn succeeds(args: &[&str]) -> Output {
    let out = calib(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    out
}

fn fails(args: &[&str]) -> String {
    let out = calib(args);
    assert!(!out.status.success(), "{args:?} should fail");
    let stderr = String::from_utf8_lossy(&out.stderr).trim_end().to_owned();
    assert_eq!(stderr.lines().count(), 1, "{args:?}: not one line:\n{stderr}");
    stderr
}

/// A full-pose poe model of a simulated IRB 4400 and a three-row program.
fn setup(dir: &Path) -> (PathBuf, PathBuf) {
    let data = dir.join("sim.csv");
    let model = dir.join("poe.ron");
    succeeds(&[
        "simulate",
        "--robot",
        &fixture("irb4400.ron"),
        "--out",
        &text(&data),
        "--rows",
        "150",
        "--seed",
        "6",
        "--full-pose",
    ]);
    succeeds(&[
        "fit",
        "--robot",
        &fixture("irb4400.ron"),
        "--data",
        &text(&data),
        "--method",
        "poe",
        "--out",
        &text(&model),
    ]);
    let program = dir.join("program.csv");
    std::fs::write(
        &program,
        "q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,payload_kg,label\n0.2,0.3,-0.2,0.5,0.7,0.9,2.5,p1\n-0.5,0.1,0.3,-1.0,-0.6,0.2,2.5,p2\n",
    )
    .unwrap();
    (model, program)
}

#[test]
fn a_program_comes_out_compensated_with_its_columns_and_residuals() {
    let dir = tempfile::tempdir().unwrap();
    let (model, program) = setup(dir.path());
    let out = succeeds(&[
        "compensate",
        "--model",
        &text(&model),
        "--targets",
        &text(&program),
        "--robot",
        &fixture("irb4400.ron"),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let mut lines = stdout.lines();
    assert_eq!(
        lines.next(),
        Some(
            "q1_rad,q2_rad,q3_rad,q4_rad,q5_rad,q6_rad,nominal_q1_rad,nominal_q2_rad,nominal_q3_rad,nominal_q4_rad,\
             nominal_q5_rad,nominal_q6_rad,payload_kg,label,residual_mm,residual_mrad,status,line"
        )
    );
    for ((line, label), file_line) in lines.zip(["p1", "p2"]).zip(["2", "3"]) {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), 18, "{line}");
        assert_eq!(cells[17], file_line, "{line}");
        assert_eq!((cells[13], cells[16]), (label, "ok"), "{line}");
        assert!(cells[14].parse::<f64>().unwrap() < 1e-6, "{line}");
        assert!(cells[0].parse::<f64>().is_ok(), "{line}");
    }
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("compensated 2 of 2 targets"), "{stderr}");
    // Without --robot, the description the model keeps: the same targets.
    let kept = succeeds(&["compensate", "--model", &text(&model), "--targets", &text(&program)]);
    assert_eq!(kept.stdout, out.stdout);
    let help = String::from_utf8_lossy(&succeeds(&["compensate", "--help"]).stdout).into_owned();
    assert!(help.contains("--frame"), "{help}");
}

#[test]
fn compensate_refusals_are_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let (model, program) = setup(dir.path());
    // A model written before it kept its robot description: joint targets need --robot.
    let old = dir.path().join("old.ron");
    let kept = std::fs::read_to_string(&model).unwrap();
    let cut = kept.find("    robot_description:").expect("the model keeps its robot");
    std::fs::write(&old, format!("{})\n", &kept[..cut])).unwrap();
    let message = fails(&["compensate", "--model", &text(&old), "--targets", &text(&program)]);
    assert!(message.contains("program.csv:1:1: joint targets are a program taught on the nominal model"), "{message}");
    let message = fails(&["compensate", "--model", &text(&model), "--targets", &text(&program), "--frame", "world"]);
    assert!(message.contains("unknown frame 'world'"), "{message}");
    let message = fails(&["compensate", "--model", &text(&model), "--targets", &text(&program), "--base-link", "x"]);
    assert!(message.contains("--base-link and --tip-link need --robot"), "{message}");
}
