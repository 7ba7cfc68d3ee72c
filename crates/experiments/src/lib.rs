//! Training, evaluation, run directories, result tables and figures (spec sections 6 and 7).
//!
//! Not built yet: see the training and evaluation issue.
