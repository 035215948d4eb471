//! Synthetic parts (to be written).
