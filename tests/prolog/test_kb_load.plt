/*  plunit tests of the knowledge bases' life cycle (prolog/kb_load.pl): a dropped knowledge
    base's module is destroyed whole, through the one wrapper of SWI-Prolog's unexported
    module destruction (relrl_kb:destroy_module/1), and its name is given again, empty. Run
    from pytest (tests/prolog/test_plunit.py) or:
        swipl -g run_tests -t halt prolog/relrl.pl tests/prolog/test_kb_load.plt
*/
:- use_module(library(plunit)).
:- use_module('../../prolog/relrl').
:- use_module('../../prolog/gateway').

sis(Path) :-
    module_property(relrl, file(RelrlFile)),
    file_directory_name(RelrlFile, Dir),
    atomic_list_concat([Dir, '/../examples/domains/sis.pl'], Path).

loaded_kb(KB) :-
    relrl_gateway:gw_new_kb(KB),
    sis(Path),
    relrl_gateway:gw_load(Path, KB, Problems),
    assertion(Problems == []).

:- begin_tests(kb_life_cycle).

test(a_loaded_kb_has_its_module_and_files) :-
    loaded_kb(KB),
    assertion(current_module(KB)),
    assertion(current_predicate(KB:stimulus/1)),
    assertion(source_file_property(_, load_context(KB, _, _))),
    relrl_gateway:gw_drop_kb(KB).

test(a_dropped_kb_leaves_no_module_and_no_loaded_file) :-
    loaded_kb(KB),
    relrl_gateway:gw_drop_kb(KB),
    assertion(\+ current_module(KB)),
    assertion(\+ source_file_property(_, load_context(KB, _, _))),
    assertion(\+ relrl_kb:kb_module(KB)).

test(a_dropped_kbs_name_is_given_again_empty, [KB2 == KB]) :-
    loaded_kb(KB),
    relrl_gateway:gw_drop_kb(KB),
    relrl_gateway:gw_new_kb(KB2),
    assertion(\+ current_predicate(KB2:stimulus/1)),
    relrl_gateway:gw_drop_kb(KB2).

test(drop_twice_is_harmless) :-
    loaded_kb(KB),
    relrl_gateway:gw_drop_kb(KB),
    relrl_gateway:gw_drop_kb(KB).

:- end_tests(kb_life_cycle).
