//! Writing results to files.
