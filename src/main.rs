//! The `geartherm` command-line binary: parse, run, print, exit code.
mod cli;

use std::io::Write;

use clap::Parser;

fn main() {
    // Usage errors exit 1 like any other bad input (clap's own default is 2, which is this
    // tool's code for a numerical failure); --help and --version exit 0.
    let args = match cli::Cli::try_parse() {
        Ok(a) => a,
        Err(e) => {
            let _ = e.print();
            std::process::exit(if e.use_stderr() { 1 } else { 0 });
        }
    };
    if let Err(f) = cli::run(args) {
        if !f.message.is_empty() {
            let newline = if f.message.ends_with('\n') { "" } else { "\n" };
            let _ = write!(std::io::stderr(), "{}{newline}", f.message);
        }
        std::process::exit(f.code);
    }
}
