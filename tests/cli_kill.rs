//! Fault test (issue 15): `eij identify` with four outputs (machine file, report, stiffness table,
//! figure) over an old set, killed at random moments by SIGTERM or SIGKILL. Afterwards the
//! outputs are all old or all new, never mixed, and no temporary file is left: SIGTERM during
//! the commit is held until it ends; a SIGKILL inside the commit's renames leaves a journal that
//! the next commit of those outputs completes (`eij::io` module docs).

mod common;

use common::mutation::Rng;
use common::Scratch;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const OUTPUTS: [&str; 4] = ["id.toml", "id.json", "id.csv", "id.svg"];

fn args(s: &Scratch) -> Vec<String> {
    let mut v = common::identify_args(&s.s(OUTPUTS[0]), &s.s(OUTPUTS[1]));
    v.push("--quiet".into());
    for (flag, name) in ["--stiffness-out", "--plot"].into_iter().zip(&OUTPUTS[2..]) {
        v.push(flag.into());
        v.push(s.s(name));
    }
    v
}

fn spawn(s: &Scratch) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_eij"))
        .current_dir(common::root())
        .args(args(s))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

fn leftovers(s: &Scratch) -> Vec<String> {
    std::fs::read_dir(&s.0)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".eij-"))
        .collect()
}

#[test]
fn a_killed_identify_leaves_the_old_or_the_new_set() {
    let s = Scratch::new("kill");
    let old = |name: &str| format!("old {name}\n");
    let start = Instant::now();
    assert!(spawn(&s).wait().unwrap().success());
    let run_time = start.elapsed();
    let mut rng = Rng(15);
    let (mut saw_old, mut saw_new) = (0, 0);
    for i in 0..16 {
        for name in OUTPUTS {
            s.write(name, old(name));
        }
        // Delays over the whole run, the commit at its end included; the first at once; the
        // last run is not killed (it must give the new set whatever the machine's load).
        let delay = match i {
            0 => Duration::ZERO,
            _ => run_time.mul_f64(1.3 * rng.below(1000) as f64 / 1000.0),
        };
        let signal = if i % 2 == 0 {
            libc::SIGTERM
        } else {
            libc::SIGKILL
        };
        let mut child = spawn(&s);
        if i < 15 {
            std::thread::sleep(delay);
            // SAFETY: signals our own child, which has not been waited for yet.
            unsafe {
                libc::kill(child.id() as libc::pid_t, signal);
            }
        }
        child.wait().unwrap();
        let left = leftovers(&s);
        if !left.is_empty() {
            assert_eq!(signal, libc::SIGKILL, "SIGTERM left {left:?}");
            // The next commit of these outputs completes or drops the killed one's, in its
            // first step (recovery), whichever folder it starts from.
            let dir = s.0.canonicalize().unwrap();
            let outputs: Vec<std::path::PathBuf> = OUTPUTS.iter().map(|n| dir.join(n)).collect();
            eij::io::recover(&dir, &outputs);
            assert!(leftovers(&s).is_empty(), "{:?}", leftovers(&s));
        }
        let contents: Vec<String> = OUTPUTS
            .iter()
            .map(|n| std::fs::read_to_string(s.path(n)).unwrap())
            .collect();
        let olds = OUTPUTS
            .iter()
            .zip(&contents)
            .filter(|(n, c)| **c == old(n))
            .count();
        assert!(
            olds == 0 || olds == OUTPUTS.len(),
            "run {i} (signal {signal} after {delay:?}): {olds} old and {} new outputs",
            OUTPUTS.len() - olds
        );
        if olds == 0 {
            saw_new += 1;
            assert!(contents[0].contains("[[axis]]") && contents[1].starts_with('{'));
        } else {
            saw_old += 1;
        }
    }
    eprintln!(
        "killed runs: {saw_old} old set, {} new set (the last run, not killed, new)",
        saw_new - 1
    );
    // Both outcomes occurred: the kills fell before and after the commit.
    assert!(saw_old > 0 && saw_new > 0, "old {saw_old}, new {saw_new}");
}
