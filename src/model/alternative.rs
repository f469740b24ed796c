//! Model-form alternatives: every model choice of a loss source that the model's data allow,
//! resolved with the same checks as the choice written in the file, or why it is not
//! applicable. The scene compiles them only when a job asks for the model-form spread
//! (docs/uq.md, "Model-form spread").

/// One model choice of a loss source.
#[derive(Debug, Clone, PartialEq)]
pub struct Alternative<T> {
    /// The choice's name as the model file writes it (`seetharaman`, `skf_older`).
    pub choice: &'static str,
    /// True for the choice the model file makes (written or by default).
    pub default: bool,
    /// The resolved model, or why the model's data do not allow it (the first problem its
    /// checks report).
    pub model: Result<T, String>,
}

impl<T> Alternative<T> {
    /// The alternative `choice` from the problems its checks reported (`found` is what they
    /// resolved).
    pub fn checked(
        choice: &'static str,
        default: bool,
        found: Option<T>,
        problems: crate::model::problems::Problems,
    ) -> Alternative<T> {
        let model = match (found, problems.as_slice().first()) {
            (Some(m), None) => Ok(m),
            (_, Some(p)) => Err(p.to_string()),
            (None, None) => Err("not resolved".to_string()),
        };
        Alternative {
            choice,
            default,
            model,
        }
    }
}
