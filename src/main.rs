//! The `geartherm` command-line binary: the library's command line ([`geartherm::cli_main`])
//! on this process's arguments, and its exit code.

fn main() {
    let code = geartherm::cli_main(std::env::args_os());
    if code != 0 {
        std::process::exit(code);
    }
}
