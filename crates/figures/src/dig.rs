//! Figures and tables of the `dig` job (filled as the job moves out of the CLI).
