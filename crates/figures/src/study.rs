//! Figures and tables of the `study` job (filled as the job moves out of the CLI).
