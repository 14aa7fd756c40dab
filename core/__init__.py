"""The ground floor: spans, diagnostics, the located YAML loader, files, git, numbers and
the cache location. It imports nothing of mpc above it."""
