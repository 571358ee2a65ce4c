:- module(relrl_learners,
          [ learner_catalogue/1     % -Learners
          ]).
:- use_module(library(error)).
:- use_module(library(apply)).
:- use_module(library(lists)).
:- use_module(engine, []).

/** <module> The learners the engine knows

Each learner is a module that adds clauses to the engine's hooks (engine.pl). Loading it
here is all it takes to make a learner available by name, to Prolog and to Python alike.

Beside its hooks, a learner declares what a user chooses it by:

  - learner_parameter(Name, Param, Default, Kind), one per parameter in the order they
    are listed: Default a number of Kind, one of `unit` ([0, 1]), `open_unit` ((0, 1)),
    `nonneg` (>= 0), whole(Min) (a whole number >= Min), `flag` (0 or 1) or `number`;
  - learner_serves(Name, Family, Overrides), one per family of tasks it learns:
    `domains` (the domains of the simulator and the robot, whose state is the code of the
    domain's features or the relational view of working memory) or `worlds` (worlds
    written in Prolog, world.pl: the learner must declare view(relational)). Overrides are
    Param=Value defaults of that family, where they differ from the learner's own.

A learner that declares learner_property(Name, external) is the engine's side of learners
that choose in Python; they declare their parameters in Python and it declares none.
learner_catalogue/1 is what Python asks when it starts: its registry of learners is built
from it alone, in the order the files below are loaded (the order experiments list them
in).
*/

%!  learner_catalogue(-Learners:list) is det.
%
%   Learners is learner(Name, Properties, Parameters, Serves) for every registered
%   learner (relrl_engine:learner/1), in the order they were loaded: Properties its learner_property/2
%   declarations (sorted), Parameters its parameter(Param, Default, Kind) in the order
%   declared, Serves its serves(Family, Overrides).
%
%   @error learner_declaration(Name, Problem) if a learner's declarations are
%   incomplete or inconsistent (see check_learner/4), or a declaration names a learner
%   that is not registered.

learner_catalogue(Learners) :-
    findall(Name, relrl_engine:learner(Name), Names0),
    list_to_set(Names0, Names),
    forall(( ( relrl_engine:learner_parameter(Other, _, _, _)
             ; relrl_engine:learner_serves(Other, _, _) ),
             \+ memberchk(Other, Names) ),
           declaration_error(Other, 'declares parameters or tasks but is not registered \c
                                     (learner/1)')),
    maplist(catalogue_entry, Names, Learners).

catalogue_entry(Name, learner(Name, Properties, Parameters, Serves)) :-
    findall(P, relrl_engine:learner_property(Name, P), Properties0),
    sort(Properties0, Properties),
    findall(parameter(P, D, K), relrl_engine:learner_parameter(Name, P, D, K), Parameters),
    findall(serves(F, O), relrl_engine:learner_serves(Name, F, O), Serves),
    check_learner(Name, Properties, Parameters, Serves).

%   check_learner(+Name, +Properties, +Parameters, +Serves) is det.
%
%   Every parameter is named once, with a kind (a name) and a number as its default; an
%   external learner declares no parameters and serves no family, any other serves at
%   least one, each once, with overrides of its own parameters by numbers; a learner of
%   worlds reads the relational view (view(relational)). Whether a number is a value of
%   its parameter's kind Python checks when it builds its registry.

check_learner(Name, Properties, Parameters, Serves) :-
    forall(member(parameter(P, D, K), Parameters), check_parameter(Name, P, D, K)),
    findall(P, member(parameter(P, _, _), Parameters), Ps),
    (   msort(Ps, Sorted), sort(Ps, Sorted)
    ->  true
    ;   declaration_error(Name, 'declares a parameter twice')
    ),
    findall(F, member(serves(F, _), Serves), Fs),
    (   memberchk(external, Properties)
    ->  (   Parameters == [], Serves == []
        ->  true
        ;   declaration_error(Name, 'is external: its learners declare their parameters \c
                                     and tasks in Python')
        )
    ;   Fs == []
    ->  declaration_error(Name, 'serves no family of tasks (learner_serves/3)')
    ;   msort(Fs, SortedFs), sort(Fs, SortedFs)
    ->  forall(member(serves(F, O), Serves),
               check_serves(Name, Properties, Parameters, F, O))
    ;   declaration_error(Name, 'serves a family of tasks twice')
    ).

check_parameter(Name, P, D, K) :-
    (   atom(P)
    ->  true
    ;   declaration_error(Name, format('parameter ~q is not an atom', [P]))
    ),
    (   callable(K)
    ->  true
    ;   declaration_error(Name, format('parameter ~q: its kind ~q is not a name', [P, K]))
    ),
    check_value(Name, P, D).

check_serves(Name, Properties, Parameters, Family, Overrides) :-
    (   memberchk(Family, [domains, worlds])
    ->  true
    ;   declaration_error(Name, format('unknown family of tasks ~q (domains, worlds)',
                                       [Family]))
    ),
    (   Family == worlds, \+ memberchk(view(relational), Properties)
    ->  declaration_error(Name, 'serves worlds but does not read the relational view \c
                                 (view(relational))')
    ;   true
    ),
    (   is_list(Overrides)
    ->  true
    ;   declaration_error(Name, format('the overrides of ~q are not a list', [Family]))
    ),
    forall(member(O, Overrides),
           (   O = (P = V), memberchk(parameter(P, _, _), Parameters)
           ->  check_value(Name, P, V)
           ;   declaration_error(Name, format('~q: ~q overrides no parameter of it',
                                              [Family, O]))
           )).

%   A default or an override is a number: whether it is one of its parameter's kind (unit,
%   whole(Min), ...) Python checks, the one reader of kinds (relrl/learners/base.py).
check_value(Name, P, V) :-
    (   number(V)
    ->  true
    ;   declaration_error(Name, format('parameter ~q: ~q is not a number', [P, V]))
    ).

declaration_error(Name, format(Format, Args)) :-
    !,
    format(atom(Problem), Format, Args),
    throw(error(learner_declaration(Name, Problem), _)).
declaration_error(Name, Problem) :-
    throw(error(learner_declaration(Name, Problem), _)).

:- multifile prolog:error_message//1.

prolog:error_message(learner_declaration(Name, Problem)) -->
    [ 'learner ~q: ~w'-[Name, Problem] ].

:- use_module(contingency).
:- use_module(etg).
:- use_module(external).
:- use_module(tg).
:- use_module(ptg).
:- use_module(world_qtable).
