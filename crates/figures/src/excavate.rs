//! Figures and tables of the `excavate` job (filled as the job moves out of the CLI).
