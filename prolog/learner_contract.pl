:- module(relrl_learner_contract,
          [ learner_capabilities/2, % +Learner, -Caps
            capability_hooks/2,     % ?Capability, ?Hooks
            learner_hook/1,         % +Goal
            learner_hook_failed/2   % +Learner, +Hook
          ]).
:- use_module(library(lists)).

/** <module> What a learner must provide, and calling it

A learner plugs into the engine by clauses of the engine's multifile hooks
(relrl_engine:learner_init/3, learner_choose/7, ...; the table in engine.pl). This module
holds the contract: which hooks every learner has and which come with each capability it
declares (learner_capabilities/2, capability_hooks/2, checked when a run is configured),
and the one way a hook is called (learner_hook/1: a hook that fails is an error naming
it). Its errors are printed by the messages below.
*/

%!  learner_capabilities(+Learner, -Caps:list) is det.
%
%   Caps are Learner's declared properties (learner_property/2), once its hooks are
%   checked: every learner has learner_init/3, learner_forget/2, learner_update/3 and
%   learner_explain/5, and learner_choose/7 unless it is `external`; it has the hooks of
%   each capability it declares (capability_hooks/2), and no clause of an optional hook it
%   does not declare (a hook the engine would never call is a mistake, not a default).
%
%   @error learner_hooks(Learner, Problems) listing missing(Hook) and
%   undeclared(Capability, Hook) problems.

learner_capabilities(Learner, Caps) :-
    findall(P, relrl_engine:learner_property(Learner, P), Caps0),
    sort(Caps0, Caps),
    (   memberchk(external, Caps)
    ->  Required = [learner_init/3, learner_forget/2, learner_update/3, learner_explain/5]
    ;   Required = [learner_init/3, learner_forget/2, learner_update/3, learner_explain/5,
                    learner_choose/7]
    ),
    findall(missing(H), ( member(H, Required), \+ has_hook(Learner, H) ), Missing),
    findall(Problem,
            ( capability_hooks(Cap, Hooks),
              member(H, Hooks),
              (   memberchk(Cap, Caps)
              ->  \+ has_hook(Learner, H),
                  Problem = missing(H)
              ;   has_hook(Learner, H),
                  Problem = undeclared(Cap, H)
              ) ),
            Declared),
    append(Missing, Declared, Problems),
    (   Problems == []
    ->  true
    ;   throw(error(learner_hooks(Learner, Problems), _))
    ).

%!  capability_hooks(?Capability, ?Hooks:list) is nondet.
%
%   The optional hooks a learner has when it declares learner_property(Name, Capability).

capability_hooks(state, [learner_state/4]).
capability_hooks(size, [learner_size/3]).
capability_hooks(policy, [learner_save/3, learner_restore/3, learner_policy_term/2]).
capability_hooks(policy_info, [learner_policy_info/3]).
capability_hooks(text, [learner_text/3]).
capability_hooks(graph, [learner_graph/3]).
capability_hooks(knowledge, [learner_knowledge/3]).
capability_hooks(end_episode, [learner_end_episode/2]).
capability_hooks(snapshot, [learner_snapshot/3, learner_resume/3]).

%   Learner has a clause of hook Name/Arity (its first argument is the learner's name).
has_hook(Learner, Name/Arity) :-
    functor(Head, Name, Arity),
    arg(1, Head, Learner),
    \+ \+ clause(relrl_engine:Head, _).

%!  learner_hook(+Goal) is det.
%
%   Call Goal, a learner's hook (learner_init(Name, ...), learner_choose(Name, ...) ...,
%   the engine's multifile predicates), which must succeed: a hook that fails is an error
%   naming it (an exception it raises goes on as it is).
%
%   @error learner_hook_failed(Learner, Name/Arity) if the hook fails.

%   (The argument is module-sensitive only so that a cross-referencer does not look for the
%   hook in the caller's module: a hook is always the engine's.)

:- meta_predicate learner_hook(:).

learner_hook(Goal0) :-
    strip_module(Goal0, _, Goal),
    (   relrl_engine:Goal
    ->  true
    ;   functor(Goal, Name, Arity),
        arg(1, Goal, Learner),
        learner_hook_failed(Learner, Name/Arity)
    ).

%!  learner_hook_failed(+Learner, +Hook) is det.
%
%   Throw the error of Learner's Hook (Name/Arity) that failed: for a caller that calls a
%   hook itself on its hot path (engine_step/6).

learner_hook_failed(Learner, Hook) :-
    throw(error(learner_hook_failed(Learner, Hook), _)).

:- multifile prolog:error_message//1.

prolog:error_message(learner_hooks(Learner, Problems)) -->
    [ 'learner ~q: '-[Learner] ],
    hook_problems(Problems).
prolog:error_message(learner_capability(Learner, Cap)) -->
    [ 'learner ~q has no capability ~q (learner_property/2)'-[Learner, Cap] ].
prolog:error_message(learner_hook_failed(Learner, learner_update/3)) --> !,
    [ 'learner ~q: its hook learner_update/3 failed (a hook must succeed; it is given '-
      [Learner],
      'transition(S0, A0, N0, Allowed0, R, Reinforced, S1, N1, Allowed1))' ].
prolog:error_message(learner_hook_failed(Learner, Hook)) -->
    [ 'learner ~q: its hook ~q failed (a hook must succeed)'-[Learner, Hook] ].

hook_problems([]) --> [].
hook_problems([P|Ps]) -->
    hook_problem(P),
    (   { Ps == [] }
    ->  []
    ;   [ '; ' ],
        hook_problems(Ps)
    ).

hook_problem(missing(H)) -->
    [ 'no ~q hook'-[H] ].
hook_problem(undeclared(Cap, H)) -->
    [ 'has ~q but does not declare learner_property(_, ~q)'-[H, Cap] ].
