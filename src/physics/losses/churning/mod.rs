//! churning losses (placeholder, being written).
