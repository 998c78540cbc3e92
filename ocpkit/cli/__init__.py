"""The `ocpkit` command line: one module per command family (`ocpkit.cli.main` parses and dispatches)."""
