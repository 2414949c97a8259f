//! The `caustic` command line: one file per command under `src/cli/`.

mod cli;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    restore_sigpipe();
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{}", error_text(&e));
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

/// The message of a failed command, every error line starting with `error:`. Usage and
/// golden-check errors carry the prefix in their own text, as do scene diagnostics (their own
/// `error:` lines) and image-output errors; an interruption is reported as `interrupted:`; the
/// rest get it here.
fn error_text(e: &caustic::Error) -> String {
    let text = e.to_string();
    match e {
        caustic::Error::Scene(caustic::scene::SceneError::Invalid(_))
        | caustic::Error::Interrupted(_) => text,
        _ if text.starts_with("error:") => text,
        _ => format!("error: {text}"),
    }
}

/// Lets a closed standard output end the program quietly, as it does every Unix tool
/// (`caustic compare a.exr b.exr | head -1`): Rust ignores SIGPIPE, which would turn the failed
/// write into a panic.
#[cfg(unix)]
fn restore_sigpipe() {
    // POSIX `signal(SIGPIPE, SIG_DFL)`; SIGPIPE is 13 and SIG_DFL is 0 on Linux and macOS.
    unsafe extern "C" {
        fn signal(signum: i32, handler: usize) -> usize;
    }
    // SAFETY: called first thing in `main`, before any thread starts; resetting a signal's
    // disposition to the default touches no Rust state.
    unsafe {
        signal(13, 0);
    }
}

#[cfg(not(unix))]
fn restore_sigpipe() {}
