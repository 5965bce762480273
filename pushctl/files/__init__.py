"""Files pushctl writes and reads: atomic writes and the provenance line every results file
starts with (:mod:`.provenance`), the lock that keeps a command from overwriting results it
did not make (:mod:`.output_guard`), and TOML files read with one-line errors
(:mod:`.toml`)."""
