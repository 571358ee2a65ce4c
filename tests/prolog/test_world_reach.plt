/*  plunit tests of world_reachable/5: a task instance whose goal no state of the world can
    hold is told from one that a search reaches, and from one the search cannot decide.
*/
:- use_module(library(plunit)).
:- use_module('../../prolog/relrl').
:- use_module('../../prolog/gateway').
:- use_module('../../prolog/world').

blocks(KB) :-
    module_property(relrl, file(RelrlFile)),
    file_directory_name(RelrlFile, Dir),
    atomic_list_concat([Dir, '/../examples/worlds/blocks.pl'], Path),
    relrl_gateway:gw_new_kb(KB),
    relrl_gateway:gw_load(Path, KB, Problems),
    assertion(Problems == []).

:- begin_tests(world_reachable).

test(an_instance_the_world_reaches, V == reachable) :-
    blocks(KB),
    world_reachable(KB, on(b1, b2), 3, 2000, V).

test(a_block_on_itself, V == unreachable) :-
    blocks(KB),
    world_reachable(KB, on(b1, b1), 3, 2000, V).

test(a_block_the_world_does_not_have, V == unreachable) :-
    blocks(KB),
    world_reachable(KB, on(b1, b4), 3, 2000, V).

test(too_many_states_to_tell, V == unknown) :-
    blocks(KB),
    world_reachable(KB, on(b1, b1), 8, 50, V).

test(size_must_be_positive, error(type_error(positive_integer, 0))) :-
    blocks(KB),
    world_reachable(KB, stack, 0, 10, _).

:- end_tests(world_reachable).
