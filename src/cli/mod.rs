//! Command-line interface: argument definitions and command dispatch. Parses, calls the library,
//! prints, and maps errors to exit codes (0 ok, 1 invalid input, 2 numerical failure, 3 I/O).

use std::path::PathBuf;

use clap::{Parser, Subcommand};

use geartherm::model::{self, ModelError};
use geartherm::report::info;

/// Exit code: invalid input (nothing written).
pub const EXIT_INVALID: i32 = 1;
/// Exit code: numerical failure.
#[allow(dead_code)]
pub const EXIT_NUMERICAL: i32 = 2;
/// Exit code: I/O failure while writing outputs.
pub const EXIT_IO: i32 = 3;

/// geartherm: gearbox power losses and temperatures over drive cycles.
#[derive(Parser, Debug)]
#[command(name = "geartherm", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Commands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Validate a model file and list every problem (exit 1 if any).
    Check {
        /// Model file (TOML).
        model: PathBuf,
    },
    /// Gear states with ratios, member speeds per unit input, meshes with contact ratios, immersion.
    Info {
        /// Model file (TOML).
        model: PathBuf,
        /// Print one JSON document instead of tables.
        #[arg(long)]
        json: bool,
    },
}

/// A failure with its exit code and message.
pub struct Failure {
    /// Exit code.
    pub code: i32,
    /// Message for stderr.
    pub message: String,
}

impl From<ModelError> for Failure {
    fn from(e: ModelError) -> Self {
        Failure {
            code: EXIT_INVALID,
            message: e.report(),
        }
    }
}

/// Run a parsed command line.
pub fn run(cli: Cli) -> Result<(), Failure> {
    match cli.command {
        Command::Check { model } => {
            let gb = model::load(&model)?;
            println!(
                "{}: ok ({} gears, {} meshes, {} gear states)",
                model.display(),
                gb.gears.len(),
                gb.meshes.len(),
                gb.gear_states.len()
            );
            Ok(())
        }
        Command::Info { model, json } => {
            let gb = model::load(&model)?;
            let report = info::info(&gb);
            if json {
                let text = serde_json::to_string_pretty(&report).map_err(|e| Failure {
                    code: EXIT_IO,
                    message: format!("cannot serialise the report: {e}"),
                })?;
                println!("{text}");
            } else {
                print!("{}", info::to_text(&report, &gb));
            }
            Ok(())
        }
    }
}
