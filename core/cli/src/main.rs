//! The `foton` command. All of it lives in the library (`foton_cli`) so that it can be tested
//! in-process; this file only hands over the arguments and the exit code.

fn main() -> std::process::ExitCode {
    foton_cli::install_interrupt_handler();
    let args: Vec<std::ffi::OsString> = std::env::args_os().collect();
    let code = foton_cli::run(args, &mut std::io::stdout(), &mut std::io::stderr());
    std::process::ExitCode::from(code)
}
