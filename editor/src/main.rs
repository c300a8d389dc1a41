//! `hairloom`: the editor, and the command-line tools in [`cli`].

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
