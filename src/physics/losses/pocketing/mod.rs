//! pocketing losses (placeholder, being written).
