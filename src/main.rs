//! The `caustic` command line: one file per command under `src/cli/`.

mod cli;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{}", error_text(&e));
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

/// The message of a failed command, every error line starting with `error:` (scene diagnostics
/// already carry their own `error:` lines; an interruption is reported as `interrupted:`).
fn error_text(e: &caustic::Error) -> String {
    let text = e.to_string();
    match e {
        caustic::Error::Scene(caustic::scene::SceneError::Invalid(_))
        | caustic::Error::Interrupted(_) => text,
        _ if text.starts_with("error:") => text,
        _ => format!("error: {text}"),
    }
}
