//! Job options by name: the use-case layer names an option as study files and Python do
//! (`speed_rpm`); each front end adds its own spelling. The command line's is written here
//! once, for the CLI and for the stand-alone command lines [`super::command`] renders: `--`
//! and the name with `-` for `_` (`--speed-rpm`), as clap derives the flags from the same field
//! names.

/// The command-line flag of option `name` (`speed_rpm` → `--speed-rpm`).
pub fn flag(name: &str) -> String {
    format!("--{}", name.replace('_', "-"))
}

/// `message` as the command line shows it: an option named at the message's start (the
/// option of the error's first problem) is followed by its flag, `speed_rpm (--speed-rpm) = …`.
pub fn spelled_for_cli(message: &str, option: Option<&str>) -> String {
    match option {
        Some(name) if !name.is_empty() && message.starts_with(name) => {
            let rest = &message[name.len()..];
            if !rest.starts_with(|c: char| c.is_alphanumeric() || c == '_') {
                format!("{name} ({}){rest}", flag(name))
            } else {
                message.to_string()
            }
        }
        _ => message.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cli_adds_the_flag_after_a_leading_option_name_only() {
        assert_eq!(flag("speed_rpm"), "--speed-rpm");
        assert_eq!(
            spelled_for_cli(
                "speed_rpm = -5 rpm: must lie in [0, 50000] rpm",
                Some("speed_rpm")
            ),
            "speed_rpm (--speed-rpm) = -5 rpm: must lie in [0, 50000] rpm"
        );
        // A study's key path in front, or another name, is left as it is.
        let m = "job.options: rtol = 0.5: must lie in [1e-14, 0.1]";
        assert_eq!(spelled_for_cli(m, Some("rtol")), m);
        assert_eq!(spelled_for_cli("rtolx = 1", Some("rtol")), "rtolx = 1");
    }
}
