//! Figures and tables of the `perceive` job (filled as the job moves out of the CLI).
