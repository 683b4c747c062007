//! Plant to mesh. (being written)
