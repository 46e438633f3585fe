//! Adding-doubling: exact plane-parallel transport for layered slabs (issue [exact]); in progress.
