//! The `yawcast` command-line tool: exit code 0 on success, 2 on bad input, 1 otherwise;
//! 130 (SIGINT) or 143 (SIGTERM) when interrupted, with no output half-written.

use std::io::Write;
use std::process::ExitCode;

use clap::Parser;

mod cli;

fn main() -> ExitCode {
    let parsed = match cli::Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            // Help and version go to stdout with 0; argument errors are bad input (2).
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    interrupt_on_signals();
    match cli::run(parsed) {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            if let Some(signal) = err.chain().find_map(|c| match c.downcast_ref() {
                Some(yawcast::io::data::DataError::Interrupted { signal }) => Some(*signal),
                _ => None,
            }) {
                exit_interrupted(signal);
            }
            // One line with the whole cause chain first, then nothing else to scroll past.
            let _ = writeln!(std::io::stderr(), "error: {}", one_line(&err));
            if cli::common::is_bad_input(&err) {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}

/// SIGINT and SIGTERM end the process with 128 + the signal once no output is being written:
/// a write of outputs in progress rolls back (or, past its last rename, finishes) first,
/// under the lock of [`yawcast::io::data::OUTPUTS`], so no temporary file, backup or part
/// of a command's outputs is left.
fn interrupt_on_signals() {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) else {
        // Without the handler the signals keep their default action (no worse than before).
        return;
    };
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            let _no_more_writes = yawcast::io::data::OUTPUTS.interrupt(signal);
            exit_interrupted(signal);
        }
    });
}

/// Reports the interruption once (the signal thread and the main thread may both get here)
/// and exits with 128 + the signal.
fn exit_interrupted(signal: i32) -> ! {
    static REPORTED: std::sync::Once = std::sync::Once::new();
    // The first caller exits inside `call_once`; a second one waits there until it has.
    REPORTED.call_once(|| {
        let name = match signal {
            2 => "SIGINT",
            15 => "SIGTERM",
            _ => "a signal",
        };
        // Not `eprintln!`: with stderr closed (its reader gone) that panics, and the process
        // would go on running without its signal handler.
        let _ = writeln!(
            std::io::stderr(),
            "error: interrupted by {name}: outputs not yet renamed into place were rolled back"
        );
        std::process::exit(128 + signal)
    });
    std::process::exit(128 + signal)
}

/// The cause chain on one line, each cause once: an error whose text already holds its
/// source's (`{path}: {source}`) is not followed by that source again.
fn one_line(err: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in err.chain() {
        let s = cause.to_string();
        if line.contains(&s) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&s);
    }
    line
}
