//! Software renderer. (being written)
