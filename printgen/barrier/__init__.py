"""What varies the barrier's physics, as data with one home each (beside `inputs`): the net
`patterns` (graph, membrane factor, strand law, lattice span, node count) and the `loads`
(parameters, solver loads, the assumptions each states). A new pattern or load case is one
module in its folder plus its test: the registries find it by its module name."""
