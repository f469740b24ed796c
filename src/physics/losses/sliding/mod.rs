//! sliding losses (placeholder, being written).
