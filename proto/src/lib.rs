//! Wire types of gjkd (work in progress).
