:- module(relrl_learner_hooks,
          [ learner_hooks/2       % +Learner, +Hooks
          ]).
:- use_module(library(error)).
:- use_module(library(apply)).

/** <module> A learner's hooks by delegation, declared in one line

The engine calls a learner through the multifile hooks of relrl_engine (engine.pl's
learner_init/3, learner_choose/7, ...): learner_Hook(Learner, Arguments...). A learner whose
hooks only pass their arguments on to predicates of its own module declares them with one
directive instead of a clause each:

    :- learner_hooks(tg, [init-tg_init, choose-tg_choose, update-tg_update]).

which compiles, into the file that holds the directive, the clauses

    relrl_engine:learner_init(tg, A, B) :- relrl_tg:tg_init(A, B).
    relrl_engine:learner_choose(tg, A, B, C, D, E, F) :- relrl_tg:tg_choose(A, B, C, D, E, F).
    ...

They are the clauses a learner would write by hand, compiled as the file's own (static,
indexed on the learner's name): the engine's call costs what it did. A hook that does more
than pass its arguments on (drops one, calls two predicates) is written out as a clause.
*/

%!  learner_hooks(+Learner:atom, +Hooks:list) is det.
%
%   As a directive of a learner's module: for each Hook-Predicate of Hooks, compile the
%   clause relrl_engine:learner_Hook(Learner, Args...) :- Module:Predicate(Args...), Module
%   the module being loaded and Args as many as the hook takes after the learner's name.
%   Raises a domain error for a Hook the engine does not declare.

learner_hooks(Learner, Hooks) :-
    must_be(atom, Learner),
    must_be(list, Hooks),
    prolog_load_context(module, Module),
    maplist(hook_clause(Learner, Module), Hooks, Clauses),
    compile_aux_clauses(Clauses).

hook_clause(Learner, Module, Hook-Predicate,
            (relrl_engine:Head :- Module:Body)) :-
    must_be(atom, Hook),
    must_be(atom, Predicate),
    hook_arity(Hook, Name, Arity),
    N is Arity - 1,
    length(Arguments, N),
    Head =.. [Name, Learner|Arguments],
    Body =.. [Predicate|Arguments].

%   The engine's hook learner_Hook/Arity (engine.pl declares them multifile).
hook_arity(Hook, Name, Arity) :-
    atom_concat(learner_, Hook, Name),
    (   current_predicate(relrl_engine:Name/Arity),
        functor(Head, Name, Arity),
        predicate_property(relrl_engine:Head, multifile)
    ->  true
    ;   domain_error(learner_hook, Hook)
    ).
