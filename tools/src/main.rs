//! `fovea`: the command line of the foveated path tracer (`fovea_tools::cli`).

/// Exit status 1 for errors, 128 + the signal for a run stopped by SIGINT/SIGTERM.
fn main() -> std::process::ExitCode {
    match fovea_tools::cli::run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("Error: {e:?}");
            if let Some(interrupted) = e.downcast_ref::<fovea_tools::interrupt::Interrupted>() {
                return std::process::ExitCode::from(interrupted.exit_code());
            }
            // fovea replay: 1 = a regression, 2 = bad input (everything else: 1).
            if e.downcast_ref::<fovea_tools::commands::replay::BadInput>()
                .is_some()
            {
                return std::process::ExitCode::from(2);
            }
            std::process::ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod docs_tests;
