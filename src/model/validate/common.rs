//! Helpers shared by the section validators: units, quoting, lists.

pub(super) const MM: f64 = 1e-3;
pub(super) const DEG: f64 = std::f64::consts::PI / 180.0;

pub(super) fn q(s: &str) -> String {
    format!("\"{s}\"")
}

pub(super) fn list<'a, T: AsRef<str> + 'a + ?Sized>(it: impl Iterator<Item = &'a T>) -> String {
    let v: Vec<&str> = it.map(|s| s.as_ref()).collect();
    if v.is_empty() {
        "(none)".into()
    } else {
        v.join(", ")
    }
}
