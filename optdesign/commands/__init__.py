"""CLI subcommands beyond ``reproduce``; each module registers itself with cli.command."""
