//! Exporters. (being written)
