//! The `geartherm` command-line binary: parse, run, print, exit code.
mod cli;

use clap::Parser;

fn main() {
    let args = cli::Cli::parse();
    if let Err(f) = cli::run(args) {
        eprint!("{}", f.message);
        if !f.message.ends_with('\n') {
            eprintln!();
        }
        std::process::exit(f.code);
    }
}
