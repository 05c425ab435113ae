"""The command line's commands: each module registers its subcommands with the parser
(`printgen.commands.parser`). This package imports nothing, so the command line can name
its commands before any heavy import."""

# One entry per command module; a module may register several subcommands (the parser,
# `printgen.commands.parser`, imports them).
COMMAND_MODULES = (
    "printgen.commands.targets",
    "printgen.commands.select",
    "printgen.commands.profiles",
    "printgen.commands.make",
    "printgen.commands.design",
    "printgen.commands.series",
    "printgen.commands.verify",
    "printgen.commands.check",
    "printgen.commands.panel",
    "printgen.commands.testpieces",
    "printgen.commands.bench",
    "printgen.commands.calibrate",
    "printgen.commands.example",
    "printgen.commands.init",
)
