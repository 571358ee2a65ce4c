:- module(relrl_world_qtable,
          [ qtable_q/5,           % +KB, +State, +Necessity, +Action, -Q
            qtable_size/2         % +KB, -Size
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(random)).
:- use_module(library(aggregate)).
:- use_module(engine).
:- use_module(kbstate).
:- use_module(choice).
:- use_module(declarations).
:- use_module(world, [world_action_list/2]).

/** <module> qtable: Q-learning over ground relational states (the baseline of worlds)

The honest baseline for a relational learner in a world written in Prolog: tabular
Q-learning whose table is keyed on the **ground** view of the state (world.pl's
world_view/4: every fact with its object names, e.g. [clear(b2), goal_on(b1, b3), on(b1,
floor), ...]) and the ground action. It shares nothing between two states that differ
only in the names of their objects, and a state it never met — every state of a larger
world — has q_init for every action: it cannot transfer. It is the ground-state Q-learning
the relational-RL literature compares against, run inside Prolog like the world itself
(relrl's `qlearning` learner is the same update over the domains' 2^x state code, in
Python).

Choices: Boltzmann over the allowed actions with temperature T > 0 (T = 0: epsilon-greedy)
while learning or exploring; greedy (ties at random) otherwise. Update: Q += alpha * (target
- Q), target = r + gamma * max_a' Q(s', a') (r alone when the episode ended in the goal:
the next state `terminal`). Params: alpha, gamma, epsilon, temperature, q_init.

The table is a dynamic predicate of this module only, keyed by the term hash of (state,
necessity, action), so a look-up costs a hash and a first-argument index, whatever the
table's size.
*/

:- dynamic q_/5.                  % Hash, KB, Key, Q, Visits  (Key = k(State, N, Action))

%   The parameters are the `learner` part of KB's record (kbstate.pl).
params(KB, P) :-
    kb_get(KB, learner, P0),
    (   P0 = p(_, _, _, _, _)
    ->  P = P0
    ;   existence_error(qtable, KB)
    ).

init(KB, Params) :-
    must_be(atom, KB),
    maplist(param(Params), [alpha, gamma, epsilon, temperature, q_init],
            [Alpha, Gamma, Epsilon, Tau, Qinit]),
    retractall(q_(_, KB, _, _, _)),
    kb_set(KB, learner, p(Alpha, Gamma, Epsilon, Tau, Qinit)).

param(Params, Name, Value) :-
    (   memberchk(Name=V, Params)
    ->  must_be(number, V),
        Value = V
    ;   existence_error(qtable_parameter, Name)
    ).

%!  qtable_q(+KB, +State, +Necessity, +Action, -Q) is det.
%
%   Q of Action in the ground State under Necessity: the table's entry, or q_init.

qtable_q(KB, S, N, A, Q) :-
    Key = k(S, N, A),
    term_hash(Key, H),
    (   q_(H, KB, Key, Q0, _)
    ->  Q = Q0
    ;   params(KB, p(_, _, _, _, Q))
    ).

choose(KB, S, N, Allowed0, Mode, Action) :-
    listed(Allowed0, Allowed),
    Allowed = [_|_],
    params(KB, p(_, _, Epsilon, Tau, _)),
    maplist(qtable_q(KB, S, N), Allowed, Qs),
    max_list(Qs, Best),
    (   Mode == greedy
    ->  ties(Qs, Allowed, Best, Ties),
        random_member(Action, Ties)
    ;   Tau =:= 0
    ->  (   random_float < Epsilon
        ->  random_member(Action, Allowed)
        ;   ties(Qs, Allowed, Best, Ties),
            random_member(Action, Ties)
        )
    ;   softmax_member(Qs, Allowed, Best, Tau, Action)
    ).

%   A table reads every legal action: the runner's actions(A, Goal) term (world.pl's
%   world_actions/3) as the list of its solutions, in the order found, without duplicates.
listed(Allowed, List) :-
    (   Allowed = actions(_, _)
    ->  world_action_list(Allowed, List)
    ;   List = Allowed
    ).

update(KB, transition(S0, A0, N0, _, R, _, S1, N1, Next)) :-
    params(KB, p(Alpha, Gamma, _, _, Qinit)),
    (   S1 == terminal
    ->  Allowed1 = []
    ;   listed(Next, Allowed1)
    ),
    (   ( S1 == terminal ; Allowed1 == [] )
    ->  Target = R
    ;   maplist(qtable_q(KB, S1, N1), Allowed1, Qs),
        max_list(Qs, Max),
        Target is R + Gamma * Max
    ),
    Key = k(S0, N0, A0),
    term_hash(Key, H),
    (   retract(q_(H, KB, Key, Q0, V0))
    ->  true
    ;   Q0 = Qinit, V0 = 0
    ),
    Q is Q0 + Alpha * (Target - Q0),
    V is V0 + 1,
    assertz(q_(H, KB, Key, Q, V)).

%!  qtable_size(+KB, -Size) is det.
%
%   Size is size(Positions, [entries=E, states=S]): one position per table entry.

qtable_size(KB, size(E, [entries=E, states=NS])) :-
    aggregate_all(count, q_(_, KB, _, _, _), E),
    findall(S-N, q_(_, KB, k(S, N, _), _, _), SNs),
    sort(SNs, Set),
    length(Set, NS).

save(KB, Stream) :-
    format(Stream, "% q(State, Necessity, Action, Q, Visits): Q-learning over ground states~n",
           []),
    forall(q_(_, KB, k(S, N, A), Q, V),
           portray_clause(Stream, q(S, N, A, Q, V))).

restore(KB, Terms) :-
    params(KB, _),
    maplist(check_term, Terms),
    retractall(q_(_, KB, _, _, _)),
    forall(member(q(S, N, A, Q, V), Terms),
           ( Key = k(S, N, A), term_hash(Key, H), assertz(q_(H, KB, Key, Q, V)) )).

check_term(T) :-
    (   T = q(S, N, A, Q, V), ground(S), is_list(S), ground(N-A), number(Q), integer(V)
    ->  true
    ;   domain_error(qtable_entry, T)
    ).

% ---- the engine's hooks (see engine.pl) ----------------------------------------------------

relrl_engine:learner(qtable).

relrl_engine:learner_property(qtable, Cap) :-
    member(Cap, [view(relational), state, size, policy, policy_info]).

%   Parameters (learners.pl): alpha, gamma, epsilon (with temperature 0: epsilon-greedy),
%   temperature (> 0: Boltzmann), q_init. The baseline of worlds; the domains' tabular
%   baseline is qlearning over the state code.
relrl_engine:learner_parameter(qtable, alpha, 0.5, unit).
relrl_engine:learner_parameter(qtable, gamma, 0.9, unit).
relrl_engine:learner_parameter(qtable, epsilon, 0.1, unit).
relrl_engine:learner_parameter(qtable, temperature, 0.0, nonneg).
relrl_engine:learner_parameter(qtable, q_init, 0.0, number).
relrl_engine:learner_serves(qtable, worlds, []).

relrl_engine:learner_forget(qtable, KB) :-
    retractall(q_(_, KB, _, _, _)).

relrl_engine:learner_init(qtable, KB, Params) :-
    init(KB, Params).

relrl_engine:learner_state(qtable, KB, _Code, Facts) :-
    engine_relational_state(KB, Facts).

relrl_engine:learner_choose(qtable, KB, S, N, Allowed, Mode, Action) :-
    choose(KB, S, N, Allowed, Mode, Action).

relrl_engine:learner_update(qtable, KB, Transition) :-
    update(KB, Transition).

relrl_engine:learner_explain(qtable, KB, S, N, ranked(Pairs)) :-
    findall(Q-A, q_(_, KB, k(S, N, A), Q, _), Pairs0),
    sort(1, @>=, Pairs0, Pairs).

relrl_engine:learner_size(qtable, KB, Size) :-
    qtable_size(KB, Size).

relrl_engine:learner_save(qtable, KB, Stream) :-
    save(KB, Stream).

relrl_engine:learner_policy_term(qtable, q(_, _, _, _, _)).

relrl_engine:learner_restore(qtable, KB, Terms) :-
    restore(KB, Terms).

relrl_engine:learner_policy_info(qtable, KB, [relations(Templates)]) :-
    findall(T, declared(KB, relation(T)), Templates).
