"""The top floor: the `mpc` command, one module per subcommand."""
