//! The `ncplan` binary.

fn main() -> std::process::ExitCode {
    ncplan::cli::run()
}
