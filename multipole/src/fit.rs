//! Fitting skin parameters to a colour or a reflectance spectrum (issue [fit]); in progress.
