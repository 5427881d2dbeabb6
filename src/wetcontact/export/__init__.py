"""Writers that turn the reference store into files other tools read (CSV, ...)."""
