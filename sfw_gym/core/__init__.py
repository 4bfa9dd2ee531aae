"""The foundation every layer may import: constants, errors, configuration, files, threads."""
