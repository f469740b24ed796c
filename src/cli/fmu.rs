//! `fmu`: export a model as an FMI 2.0 co-simulation FMU (`job::fmu`). The runtime library is
//! found through `GEARTHERM_FMU_RUNTIME` or beside the executable; the FMU is written to a
//! temporary file in the output's directory and renamed into place (nothing written on error).

use std::path::{Path, PathBuf};

use crate::job::fmu::{self as job_fmu, FmuOptions};
use crate::report::files::write_file_atomic;

use super::output::{emit, invalid, io_failure};
use super::{Failure, ModelSource};

/// Arguments of `fmu`.
#[derive(clap::Args, Debug)]
pub struct FmuArgs {
    #[command(flatten)]
    pub source: ModelSource,
    /// The FMU to write (NAME.fmu; NAME, made a C identifier, is the model identifier).
    #[arg(long)]
    pub out: PathBuf,
    /// Export this model value as an FMU parameter, by its key path (repeatable; checked like
    /// --set: the path must exist and hold a number).
    #[arg(long = "param", value_name = "KEYPATH")]
    pub params: Vec<String>,
}

/// The runtime library: `$GEARTHERM_FMU_RUNTIME`, else `libgeartherm_fmu.so` beside the
/// running executable.
pub fn runtime_path() -> Result<PathBuf, Failure> {
    if let Some(p) = std::env::var_os(job_fmu::RUNTIME_ENV) {
        return Ok(PathBuf::from(p));
    }
    let exe = std::env::current_exe()
        .map_err(|e| io_failure(format!("cannot find the running executable: {e}")))?;
    Ok(exe.with_file_name(job_fmu::RUNTIME_FILE))
}

/// Run `fmu`.
pub fn fmu(a: &FmuArgs) -> Result<(), Failure> {
    let stem = a.out.file_stem().map(|s| s.to_string_lossy().into_owned());
    let Some(stem) = stem.filter(|_| a.out.extension().is_some_and(|e| e == "fmu")) else {
        return Err(invalid(format!(
            "--out {}: the FMU's file name must end in .fmu",
            a.out.display()
        )));
    };
    let model = &a.source.model;
    let text = std::fs::read_to_string(model)
        .map_err(|e| io_failure(format!("{}: cannot read: {e}", model.display())))?;
    let o = FmuOptions {
        params: a.params.clone(),
        model_identifier: job_fmu::model_identifier(&stem),
    };
    let overrides: Vec<String> = a.source.set.iter().map(|o| o.to_string()).collect();
    let export = job_fmu::prepare(&text, &model.display().to_string(), &overrides, &o)?;
    let dir = a
        .out
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        return Err(io_failure(format!("{}: no such directory", dir.display())));
    }
    let rt = runtime_path()?;
    let runtime = std::fs::read(&rt).map_err(|e| {
        io_failure(format!(
            "{}: cannot read the FMU runtime library: {e} (build it with `cargo build --release`, or name it with {})",
            rt.display(),
            job_fmu::RUNTIME_ENV
        ))
    })?;
    let bytes = export.package(&runtime)?;
    write_file_atomic(&a.out, &bytes)
        .map_err(|e| io_failure(format!("{}: cannot write: {e}", a.out.display())))?;
    emit(&format!(
        "wrote {} (FMI 2.0 co-simulation, model identifier {}, {} variables, {} bytes)\n",
        a.out.display(),
        o.model_identifier,
        export.variables(),
        bytes.len()
    ))
}
