/*  plunit tests of the learners' declarations (prolog/learners.pl): the catalogue Python
    builds its registry from, and every learner configured with exactly its declared
    defaults (a parameter a learner reads but does not declare would stop it). Run from
    pytest (tests/prolog/test_plunit.py) or:
        swipl -g run_tests -t halt prolog/relrl.pl tests/prolog/test_learners.plt
*/
:- use_module(library(plunit)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module('../../prolog/relrl').
:- use_module('../../prolog/gateway').

root_file(Relative, Path) :-
    module_property(relrl, file(RelrlFile)),
    file_directory_name(RelrlFile, Dir),
    atomic_list_concat([Dir, '/../', Relative], Path).

kb_with(Relative, KB) :-
    relrl_gateway:gw_new_kb(KB),
    root_file(Relative, Path),
    relrl_gateway:gw_load(Path, KB, Problems),
    assertion(Problems == []).

%   Family's defaults of learner Name: its declared ones under the family's overrides, and
%   the engine's rewards.
defaults(Name, Family, [reward_positive=10.0, reward_negative= -1.0|Params]) :-
    relrl_learners:learner_catalogue(All),
    memberchk(learner(Name, _, Declared, Serves), All),
    memberchk(serves(Family, Overrides), Serves),
    findall(P=V, ( member(parameter(P, D, _), Declared),
                   ( memberchk(P=V, Overrides) -> true ; V = D ) ), Params).

serving(Family, Name) :-
    relrl_learners:learner_catalogue(All),
    member(learner(Name, _, _, Serves), All),
    memberchk(serves(Family, _), Serves).

:- begin_tests(learner_declarations).

test(catalogue_in_load_order, [Names == [contingency, etg, external, tg, ptg, qtable]]) :-
    relrl_learners:learner_catalogue(All),
    findall(N, member(learner(N, _, _, _), All), Names).

test(families, [Domains-Worlds == [contingency, etg, tg]-[tg, ptg, qtable]]) :-
    findall(N, serving(domains, N), Domains),
    findall(N, serving(worlds, N), Worlds).

test(learners_of_worlds_read_the_relational_view, [forall(serving(worlds, Name))]) :-
    once(relrl_engine:learner_property(Name, view(relational))).

test(ptg_has_tgs_parameters_and_world_defaults) :-
    defaults(tg, worlds, TG),
    defaults(ptg, worlds, PTG),
    append(TG, [p_margin=0.0, p_alpha=0.02, p_pairs=1.0], PTG).

test(domain_learners_start_with_their_declared_defaults,
     [forall(serving(domains, Name))]) :-
    kb_with('examples/domains/sis.pl', KB),
    defaults(Name, domains, Params),
    relrl_engine:engine_configure(KB, Name, Params, 0),
    relrl_gateway:gw_drop_kb(KB).

test(world_learners_start_with_their_declared_defaults,
     [forall(serving(worlds, Name))]) :-
    kb_with('examples/worlds/blocks.pl', KB),
    defaults(Name, worlds, Params),
    relrl_engine:engine_configure(KB, Name, Params, 0),
    relrl_gateway:gw_drop_kb(KB).

test(a_missing_parameter_stops_a_learner,
     [ setup(kb_with('examples/worlds/blocks.pl', KB)),
       cleanup(relrl_gateway:gw_drop_kb(KB)),
       error(existence_error(tg_parameter, alpha))
     ]) :-
    defaults(tg, worlds, Params),
    selectchk(alpha=_, Params, Fewer),
    relrl_engine:engine_configure(KB, tg, Fewer, 0).

test(only_learners_of_worlds_run_episodes,
     [ setup(kb_with('examples/worlds/blocks.pl', KB)),
       cleanup(relrl_gateway:gw_drop_kb(KB)),
       error(domain_error(world_learner, contingency))
     ]) :-
    defaults(contingency, domains, Params),
    relrl_engine:engine_configure(KB, contingency, Params, 0),
    relrl_world:world_episodes(KB, episodes(stack, [3], 1, learn, []), _).

:- end_tests(learner_declarations).

:- begin_tests(learner_hooks).

%   learner_hooks/2 compiles a hook that passes its arguments on, as written by hand.
test(a_hook_passes_its_arguments_on) :-
    clause(relrl_engine:learner_choose(tg, A, B, C, D, E, F), Body),
    assertion(Body == relrl_tg:tg_choose(A, B, C, D, E, F)).

test(an_unknown_hook_is_refused, [error(domain_error(learner_hook, nope))]) :-
    relrl_learner_hooks:hook_clause(x, m, nope-p, _).

:- end_tests(learner_hooks).
