//! Client of gjkd (work in progress).
