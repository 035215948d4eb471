//! PNG quick-looks (to be written).
