"""The ``lagrange-gen`` command line: the entry point and subcommand dispatch (main), the options
every subcommand parses alike (options), and one module per subcommand (simulate, sweep,
animate, equations). It is the outermost layer: it may import everything, nothing imports it.
``python -m lagrange_gen.cli`` runs main."""
