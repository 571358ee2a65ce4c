:- module(relrl_engine,
          [ engine_configure/4,   % +KB, +Learner, +Params, +Seed
            engine_step/5,        % +KB, +Percepts, +Emitted, +Learning, -Out
            engine_end_episode/1, % +KB
            engine_explain/2,     % +KB, -Explanation
            engine_explain_now/2, % +KB, -Explanation
            engine_tree/2,        % +KB, -Text
            engine_size/2,        % +KB, -Size
            engine_save/3,        % +KB, +File, +Header
            engine_adopt/1,       % +KB
            engine_param/3,       % +KB, ?Name, ?Value
            engine_responses/2,   % +KB, -Responses
            engine_save_random/1, % +Slot
            engine_restore_random/1, % +Slot
            engine_set_random/1   % +SeedSpec
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(random)).
:- use_module(library(pairs)).
:- use_module(memory).
:- use_module(declarations).
:- use_module(perception).
:- use_module(state).
:- use_module(responses).
:- use_module(motivation).
:- use_module(qtree).
:- use_module(etg).
:- use_module(contingency).

/** <module> The control step, inside Prolog

One call of engine_step/5 does all the knowledge work of a control step, so the robot's
loop crosses from Python into Prolog once per step:

    percepts -> working memory -> state code -> necessity units and mediator -> reward
    -> learner update for the previous step (Eq. 4 / contingency) -> allowed responses
    -> learner choice

Learners that live in Prolog (etg, contingency) choose here; a learner that lives in Python
(`external`, e.g. Q-learning over numpy) gets the state, necessity, reward and allowed
responses and chooses itself.
*/

:- dynamic
    config_/3,      % KB, Key, Value
    prev_/3.        % KB, Description, Necessity of the last step

%!  engine_param(+KB, ?Name, ?Value) is nondet.
%
%   A parameter of KB's engine (alpha, gamma, epsilon, ...).

engine_param(KB, Name, Value) :-
    config_(KB, params, Params),
    member(Name=Value, Params).

config(KB, Key, Value) :-
    (   config_(KB, Key, Value0)
    ->  Value = Value0
    ;   existence_error(engine_configuration, KB)
    ).

%!  engine_configure(+KB, +Learner, +Params:list, +Seed) is det.
%
%   Prepare KB for a run with Learner (etg, contingency or external) and Params
%   (Name=Value). Working memory, the necessity units and the learner start afresh; Seed,
%   an integer, seeds Prolog's random numbers (`none` leaves them alone).

engine_configure(KB, Learner, Params, Seed) :-
    must_be(atom, KB),
    must_be(oneof([etg, contingency, external]), Learner),
    must_be(list, Params),
    retractall(config_(KB, _, _)),
    retractall(prev_(KB, _, _)),
    state_features(KB, Features),
    findall(G, declared(KB, etg_test(G)), Extra),
    append(Features, Extra, Tests),
    length(Features, NF),
    findall(S, kb_reinforcer(KB, S), Reinforcers),
    findall(R, kb_response(KB, R), Responses),
    motivation_units(KB, Units),
    (   current_predicate(KB:forbidden/1),
        \+ predicate_property(KB:forbidden(_), imported_from(_))
    ->  Constraints = true
    ;   Constraints = false
    ),
    forall(member(K-V, [learner-Learner, params-Params, features-Features,
                        extra_tests-Extra, n_features-NF, reinforcers-Reinforcers,
                        responses-Responses, units-Units, constraints-Constraints]),
           assertz(config_(KB, K, V))),
    (   integer(Seed)
    ->  set_random(seed(Seed))
    ;   true
    ),
    wm_clear(KB),
    motivation_reset(KB),
    (   Learner == etg
    ->  etg_init(KB, Tests)
    ;   Learner == contingency
    ->  contingency_init(KB)
    ;   true
    ).

%!  engine_end_episode(+KB) is det.
%
%   End an interaction: no update will link the next step to this one; working memory and
%   the necessity units start afresh.

engine_end_episode(KB) :-
    retractall(prev_(KB, _, _)),
    wm_clear(KB),
    motivation_reset(KB).

%!  engine_step(+KB, +Percepts, +Emitted, +Learning, -Out) is det.
%
%   One control step. Percepts are this step's perception facts; Emitted is the index
%   (0-based, in declaration order) of the response emitted at the previous step, or -1;
%   Learning is `true` to update the learner from the previous step and explore,
%   `explore` to act with the learner's exploration (epsilon) without learning, `false` to
%   act greedily without learning.
%
%   Out = step(Code, Necessity, Ys, Reward, Allowed, Action): the state code, the active
%   necessity (or none), the necessity units' outputs (a list in declaration order), the
%   reward for the previous response, the allowed responses as a bit mask (bit i set when
%   response i is allowed), and the index of the learner's choice (-1 for learners outside
%   Prolog or when nothing is allowed).
%   Indices keep the bridge to Python cheap; engine_responses/2 maps them to terms.

engine_step(KB, Percepts, EmittedIx, Learning, step(Code, Active, Ys, Reward, AllowedMask,
                                                    ActionIx)) :-
    config(KB, responses, Responses),
    (   EmittedIx >= 0
    ->  nth0(EmittedIx, Responses, Emitted),
        Elements = [emitted(Emitted)|Percepts]
    ;   Emitted = none,
        Elements = Percepts
    ),
    wm_insert(KB, Elements),
    description_now(KB, Code, D),
    config(KB, units, Units),
    motivation_step(KB, Units, Outputs, Active),
    pairs_values(Outputs, Ys),
    config(KB, reinforcers, Reinforcers),
    config(KB, params, Params),
    (   reinforced(KB, Reinforcers)
    ->  Reinforced = true, memberchk(reward_positive=Reward, Params)
    ;   Reinforced = false, memberchk(reward_negative=Reward, Params)
    ),
    allowed(KB, Responses, AllowedIx, Allowed),
    foldl(set_bit, AllowedIx, 0, AllowedMask),
    config(KB, learner, Learner),
    (   Learning == true,
        Emitted \== none,
        prev_(KB, D0, N0)
    ->  learn(Learner, KB, D0, Emitted, N0, Reward, Reinforced, D, Active, Allowed, Params)
    ;   true
    ),
    choose(Learner, KB, D, Active, Allowed, Learning, Params, Action),
    (   Action == none
    ->  ActionIx = -1
    ;   nth0(ActionIx, Responses, Action)
    ->  true
    ),
    retractall(prev_(KB, _, _)),
    assertz(prev_(KB, D, Active)).

%!  engine_save_random(+Slot) is det.
%!  engine_restore_random(+Slot) is det.
%!  engine_set_random(+SeedSpec) is det.
%
%   Save the state of Prolog's random numbers under the atom Slot, restore it, or seed
%   them (seed(N)): an evaluation can draw its own numbers without changing the learner's
%   future.

engine_save_random(Slot) :-
    must_be(atom, Slot),
    random_property(state(S)),
    atom_concat('$relrl_random:', Slot, Key),
    nb_setval(Key, S).

engine_restore_random(Slot) :-
    atom_concat('$relrl_random:', Slot, Key),
    nb_getval(Key, S),
    set_random(state(S)).

engine_set_random(Spec) :-
    (   ( Spec = state(_) ; Spec = seed(_) )
    ->  set_random(Spec)
    ;   domain_error(random_spec, Spec)
    ).

%!  engine_responses(+KB, -Responses:list) is det.
%
%   The responses in the order engine_step/5 indexes them.

engine_responses(KB, Responses) :-
    config(KB, responses, Responses).

%   The state code of working memory now, and its description: the code with a bit for
%   each extra ETG test above it.
description_now(KB, Code, D) :-
    config(KB, features, Features),
    features_code(KB, Features, Code),
    config(KB, extra_tests, Extra),
    describe(KB, Extra, Code, D).

%   The description: the state code, with a bit for each extra ETG test above it.
describe(_, [], Code, Code) :- !.
describe(KB, Extra, Code, D) :-
    config(KB, n_features, NF),
    foldl(extra_bit(KB), Extra, NF-Code, _-D).

extra_bit(KB, Goal, I-D0, I1-D) :-
    I1 is I + 1,
    (   catch(once(KB:Goal), _, fail)
    ->  D is D0 \/ (1 << I)
    ;   D = D0
    ).

reinforced(KB, Reinforcers) :-
    member(S, Reinforcers),
    sense(Sense),
    Percept =.. [Sense, S],
    wm_element(KB, Percept, 0),
    !.

allowed(KB, Responses, AllowedIx, Allowed) :-
    (   config(KB, constraints, true)
    ->  findall(I-R, ( nth0(I, Responses, R), \+ forbidden(KB, R) ), Pairs)
    ;   findall(I-R, nth0(I, Responses, R), Pairs)
    ),
    pairs_keys_values(Pairs, AllowedIx, Allowed).

set_bit(I, M0, M) :-
    M is M0 \/ (1 << I).

forbidden(KB, R) :-
    catch(KB:forbidden(R), error(existence_error(procedure, _), _), fail),
    !.

learn(etg, KB, D0, A0, N0, Reward, _, D, N, Allowed, Params) :-
    etg_update(KB, D0, A0, N0, Reward, D, N, Allowed, Params).
learn(contingency, KB, D0, A0, N0, _, Reinforced, _, _, _, Params) :-
    contingency_update(KB, D0, A0, N0, Reinforced, Params).
learn(external, _, _, _, _, _, _, _, _, _, _).

choose(_, _, _, _, [], _, _, none) :- !.
choose(etg, KB, D, N, Allowed, Learning, Params0, Action) :-
    (   Learning \== false
    ->  Params = Params0
    ;   Params = [epsilon=0|Params0]
    ),
    etg_choose(KB, D, N, Allowed, Params, Action, _).
choose(contingency, KB, D, N, Allowed, _, Params, Action) :-
    contingency_choose(KB, D, N, Allowed, Params, Action).
choose(external, _, _, _, _, _, _, none).

%!  engine_explain(+KB, -Explanation) is det.
%
%   Why the learner would choose what it chooses in the last step's state.
%   etg: etg(Path, Ranked); contingency: contingency(Ranked); external: external(Code, N).

engine_explain(KB, Explanation) :-
    (   prev_(KB, D, N)
    ->  true
    ;   D = 0, N = none
    ),
    explain(KB, D, N, Explanation).

explain(KB, D, N, Explanation) :-
    config(KB, learner, Learner),
    (   Learner == etg
    ->  etg_explain(KB, D, N, explain(Path, Ranked)),
        Explanation = etg(D, N, Path, Ranked)
    ;   Learner == contingency
    ->  contingency_explain(KB, D, N, Ranked),
        Explanation = contingency(D, N, Ranked)
    ;   Explanation = external(D, N)
    ).

%!  engine_explain_now(+KB, -Explanation) is det.
%
%   As engine_explain/2, for the state in working memory now (the necessity is the one
%   the units would give now; nothing is learned or moved).

engine_explain_now(KB, Explanation) :-
    description_now(KB, _, D),
    config(KB, units, Units),
    motivation_peek(KB, Units, _, N),
    explain(KB, D, N, Explanation).

%!  engine_tree(+KB, -Text:string) is det.
%
%   The ETG tree of KB drawn as text (empty for other learners).

engine_tree(KB, Text) :-
    (   config(KB, learner, etg)
    ->  qtree_format(KB, Text)
    ;   Text = ""
    ).

%!  engine_size(+KB, -Size) is det.
%
%   The learner's memory: etg(Nodes, Leaves, Entries, Positions),
%   contingency(Rules, Positions), or external.

engine_size(KB, Size) :-
    config(KB, learner, Learner),
    (   Learner == etg
    ->  etg_size(KB, size(A, B, C, P)), Size = etg(A, B, C, P)
    ;   Learner == contingency
    ->  contingency_size(KB, size(R, P)), Size = contingency(R, P)
    ;   Size = external
    ).

%!  engine_save(+KB, +File, +Header:string) is det.
%
%   Write KB's learned knowledge to File as Prolog facts that plain swipl consults:
%   relrl_policy/2 (learner and the tests the tree uses), etg_node/2 and
%   learned_behaviour/4. The file is written next to File and renamed into place, so a
%   reader never sees half a policy.

engine_save(KB, File, Header) :-
    config(KB, learner, Learner),
    config(KB, features, Features),
    config(KB, extra_tests, Extra),
    append(Features, Extra, Tests),
    atom_concat(File, '.tmp', Tmp),
    setup_call_cleanup(
        open(Tmp, write, S, [encoding(utf8)]),
        write_policy(S, KB, Learner, Tests, Header),
        close(S)),
    rename_file(Tmp, File).

write_policy(S, KB, Learner, Tests, Header) :-
    format(S, "% ~w~n", [Header]),
    format(S, "% Consult in plain swipl, or load with: relrl shell DOMAIN.pl --policy FILE~n~n",
           []),
    format(S, ":- discontiguous etg_node/2, learned_behaviour/4.~n~n", []),
    portray_clause(S, relrl_policy(Learner, Tests)),
    nl(S),
    (   Learner == etg
    ->  forall(qtree_node(KB, Id, Node), portray_clause(S, etg_node(Id, Node)))
    ;   Learner == contingency
    ->  contingency_rules(KB, Rules),
        forall(member(behaviour(A, R, N, F), Rules),
               portray_clause(S, learned_behaviour(A, R, N, F)))
    ;   true
    ).

%!  engine_adopt(+KB) is det.
%
%   Take over the policy facts consulted into KB (relrl_policy/2, etg_node/2,
%   learned_behaviour/4) as the engine's learned knowledge.
%
%   @error domain_error(policy_tests, Tests) if the policy was learned over other tests.

engine_adopt(KB) :-
    (   declared(KB, relrl_policy(Learner, Tests))
    ->  true
    ;   existence_error(policy, KB)
    ),
    config(KB, features, Features),
    config(KB, extra_tests, Extra),
    append(Features, Extra, Mine),
    (   Tests =@= Mine
    ->  true
    ;   domain_error(policy_tests, Tests)
    ),
    config(KB, learner, Configured),
    (   Learner == Configured
    ->  true
    ;   domain_error(policy_learner(Configured), Learner)
    ),
    (   Learner == etg
    ->  findall(Id-Node, declared(KB, etg_node(Id, Node)), Nodes),
        qtree_restore(KB, Tests, Nodes)
    ;   Learner == contingency
    ->  findall(behaviour(A, R, N, F), declared(KB, learned_behaviour(A, R, N, F)), Rules),
        contingency_restore(KB, Rules)
    ;   true
    ).
