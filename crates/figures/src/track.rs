//! Figures and tables of the `track` job (filled as the job moves out of the CLI).
