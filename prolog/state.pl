:- module(relrl_state,
          [ state_features/2,     % +KB, -Features
            feature_code/3,       % +KB, ?Term, ?X
            feature_active/2,     % +KB, +Feature
            state_terms/2,        % +KB, -Terms
            state_code/2,         % +KB, -Code
            features_code/3,      % +KB, +Features, -Code
            state_plan/3,         % +KB, +Features, -Plan
            state_plan/4,         % +KB, +Features, +Reinforcers, -Plan
            plan_code/3,          % +KB, +Plan, -Code
            plan_code/4,          % +KB, +Plan, -Code, -Reinforced
            plan_code/5,          % +KB, +Record, +Plan, -Code, -Reinforced
            plan_reinforced/3,    % +Record, +Plan, -Reinforced
            state_mark/1,         % -Mark
            state_forget/1,       % +KB
            state_forget/2,       % +KB, +Mark
            state_touch/0,
            state_decode/3,       % +KB, +Code, -Terms
            state_encode/3        % +KB, +Terms, -Code
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(declarations).
:- use_module(senses).
:- use_module(rules).
:- use_module(memory).
:- use_module(kbstate, [kb_record/2]).
:- use_module(guard, [call_context/2, set_call_context/2]).
:- set_prolog_flag(optimise, true).   % arithmetic compiled inline (this file only)

/** <module> The state code

Section 3.1: every declared stimulus and fact is associated with a number x in 0..n-1, and
the state of the environment is the sum of 2^x over the stimuli and facts that hold now.
x follows declaration order, stimuli first and then facts, so a domain file always gives
the same codes. A code decodes back to its terms without loss.

A stimulus holds when it is perceived through any sense (senses.pl); a fact holds when
its goal succeeds in the knowledge base.
*/

%!  state_features(+KB, -Features:list) is det.
%
%   Features is the list of stimulus(S) and fact(F) terms of KB in code order: the element
%   at position x (0-based) has code 2^x.

state_features(KB, Features) :-
    must_be(atom, KB),
    findall(stimulus(S), kb_stimulus(KB, S), Stimuli),
    findall(fact(F), kb_fact(KB, F), Facts),
    append(Stimuli, Facts, Features).

%!  feature_code(+KB, ?Term, ?X) is nondet.
%
%   Term, a stimulus(S) or fact(F), has index X (its code is 2^X).

feature_code(KB, Term, X) :-
    state_features(KB, Features),
    nth0(X, Features, Term).

%!  feature_active(+KB, +Feature) is semidet.
%
%   Feature (stimulus(S) or fact(F)) holds now in KB.

feature_active(KB, stimulus(S)) :-
    stimulus_perceived(KB, S).
feature_active(KB, fact(F)) :-
    rule_holds(KB, F).

%!  state_terms(+KB, -Terms:list) is det.
%
%   Terms are the features of KB that hold now, in code order.

state_terms(KB, Terms) :-
    state_features(KB, Features),
    include(feature_active(KB), Features, Terms).

%!  state_code(+KB, -Code:integer) is det.
%
%   Code is the sum of 2^x over the features of KB that hold now.

state_code(KB, Code) :-
    state_features(KB, Features),
    features_code(KB, Features, Code).

%!  features_code(+KB, +Features:list, -Code:integer) is det.
%
%   Code is the sum of 2^x over the elements of Features that hold now, x being the
%   position in Features. Features is a list from state_features/2 kept by the caller
%   (the engine computes it once per run).

features_code(KB, Features, Code) :-
    features_code_(Features, KB, 1, 0, Code).

%   A tight loop: the control step runs it over every feature each time unit.
features_code_([], _, _, Code, Code).
features_code_([F|Fs], KB, Bit, Code0, Code) :-
    (   active(F, KB)
    ->  Code1 is Code0 \/ Bit
    ;   Code1 = Code0
    ),
    Bit1 is Bit << 1,
    features_code_(Fs, KB, Bit1, Code1, Code).

active(stimulus(S), KB) :-
    stimulus_perceived(KB, S).
active(fact(F), KB) :-
    rule_holds(KB, F).

%!  state_plan(+KB, +Features:list, -Plan) is det.
%!  state_plan(+KB, +Features:list, +Reinforcers:list, -Plan) is det.
%
%   Plan computes the code of Features (a list from state_features/2) with plan_code/3:
%   the same code as features_code/3, for less work, and whether a stimulus of Reinforcers
%   is sensed now (plan_code/4). The stimuli are read off working memory in one pass: each
%   memory element is looked up in a table of the percepts that perceive a stimulus (see(S),
%   hear(S), smell(S), at(S), at(S, _) — what stimulus_perceived/2 accepts) and gives its
%   stimulus's bits; a stimulus holds when perceived, whatever rules say.
%
%   A fact is its goal, run by its rules (relrl_rules:rules_program/3: errors and time
%   limits propagate as under rule_holds/2) — except a *memory fact*, whose goal only looks
%   a ground percept up in working memory (memory_fact/4; head_at(left) :-
%   memory(at(left), 0)): the same pass reads it off memory, as a stimulus. A memory fact
%   holds exactly when its goal would succeed, and its goal can raise no error, so the
%   code is the same. Once anything but a step may have redefined, traced or spied a
%   memory fact's predicate (state_touch/0), the next plan_code/4 checks the memory facts
%   again; if one is no longer, every fact runs as its goal (until the next check).
%
%   A plan lasts until state_forget/1 and relrl_rules:rules_forget/1 (the engine's).

:- dynamic
    plan_kb_/2,             % Id, KB: KB's plan (one at a time)
    plan_stimulus_/3,       % Id, Percept, Mask: Percept perceives the stimuli of Mask
    plan_fact_/4,           % Id, Percept, Any, Now: Percept (ground, one entry each)
                            % makes the memory facts of Any true, and those of Now too
                            % when it is of age 0
    plan_memory_fact_/4,    % Id, Goal, Percept, When (any or now): the memory facts
    plan_reinforcer_/2.     % Id, Percept: Percept senses a reinforcer

state_plan(KB, Features, Plan) :-
    state_plan(KB, Features, [], Plan).

state_plan(KB, Features, Reinforcers, plan(Id, Program, Goals, checked(Touch, true))) :-
    must_be(atom, KB),
    must_be(list, Features),
    must_be(list, Reinforcers),
    plan_(Features, 1, Masks0, Facts),
    stimulus_masks(Masks0, Masks),
    flag(relrl_state_plan, Id, Id + 1),
    assertz(plan_kb_(Id, KB)),
    forall(( member(S-Mask, Masks), perceives(S, Percept) ),
           assertz(plan_stimulus_(Id, Percept, Mask))),
    forall(( member(S, Reinforcers), sense(Sense), Percept =.. [Sense, S] ),
           assertz(plan_reinforcer_(Id, Percept))),
    partition(memory_fact_bit(KB, Id), Facts, MemoryFacts, OtherFacts),
    fact_masks(Id, MemoryFacts),
    touched(Touch),
    rules_program(KB, OtherFacts, Program),
    (   MemoryFacts == []
    ->  Goals = Program
    ;   rules_program(KB, Facts, Goals)
    ).

%   Goal-Bit is a memory fact (noted for plan Id).
memory_fact_bit(KB, Id, Goal-_) :-
    memory_fact(KB, Goal, Percept, When),
    assertz(plan_memory_fact_(Id, Goal, Percept, When)).

%   The table plan_fact_/4: per percept, the bits of the memory facts it makes true (at
%   any age, or at age 0).
fact_masks(Id, MemoryFacts) :-
    findall(Percept-Masks,
            ( member(Goal-Bit, MemoryFacts),
              plan_memory_fact_(Id, Goal, Percept, When),
              (   When == any
              ->  Masks = m(Bit, 0)
              ;   Masks = m(0, Bit)
              ) ),
            Facts),
    msort(Facts, Sorted),
    merge_percepts(Sorted, Percepts),
    forall(member(P-m(Any, Now), Percepts),
           assertz(plan_fact_(Id, P, Any, Now))).

merge_percepts([], []).
merge_percepts([P-m(A, N)|Ps], Percepts) :-
    (   Ps = [P1-m(A1, N1)|Ps1], P1 == P
    ->  A2 is A \/ A1,
        N2 is N \/ N1,
        merge_percepts([P-m(A2, N2)|Ps1], Percepts)
    ;   Percepts = [P-m(A, N)|Percepts1],
        merge_percepts(Ps, Percepts1)
    ).

%!  memory_fact(+KB, +Goal, -Percept, -When) is semidet.
%
%   Goal, a fact of KB, only looks Percept (ground) up in working memory, at any age
%   (When = any) or at age 0 (When = now): its predicate is KB's own, static, neither
%   multifile nor traced nor spied, and has one clause, whose body for Goal is one call of
%   relrl's percept/1 (any age), memory/2 with age 0 (now), at/2 (any age), or see/1,
%   hear/1, smell/1 or at/1 of an atomic stimulus (any age), on a ground term. Goal then
%   succeeds exactly when Percept is in memory (of age 0 for `now`), and raises no error.

memory_fact(KB, Goal, Percept, When) :-
    callable(Goal),
    current_prolog_flag(protect_static_code, false),
    copy_term(Goal, Copy),              % the clause binds nothing of the declared fact
    Head = KB:Copy,
    predicate_property(Head, number_of_clauses(1)),
    \+ predicate_property(Head, imported_from(_)),
    \+ predicate_property(Head, dynamic),
    \+ predicate_property(Head, multifile),
    \+ predicate_property(Head, wrapped(_)),
    \+ predicate_property(Head, spying),
    clause(Head, Body),
    reads_memory(Body, Percept, When),
    ground(Percept),
    functor(Body, Name, Arity),
    functor(Callee, Name, Arity),
    predicate_property(KB:Callee, imported_from(relrl)).

reads_memory(percept(P), P, any).
reads_memory(memory(P, Age), P, now) :-
    Age == 0.
reads_memory(at(S, Place), at(S, Place), any).
reads_memory(Body, Body, any) :-
    compound(Body),
    compound_name_arguments(Body, Sense, [S]),
    sense(Sense),
    atomic(S).

%!  state_touch is det.
%
%   Anything may have changed the domain's rules since the last step (a user's query, a
%   file loaded, a trace point set): each plan checks its memory facts again at its next
%   use (see state_plan/4). relrl's gateway calls it before every call that may change
%   the domain's rules (a goal of a knowledge base, a user's query, loading a file); a
%   Prolog program that does so between steps itself calls it too. Checking costs about
%   50 us once (Experiment 1's 17 memory facts). Not covered: a domain rule that itself
%   consults a file, wraps or spies a predicate while a step (or an engine call that runs
%   rules) is running; and in debug mode the tracer does not show memory facts' calls.

state_touch :-
    touched(T0),
    T is T0 + 1,
    set_call_context(state_touch, T).

touched(T) :-
    call_context(state_touch, T).

%   Plan Id's memory facts are memory facts still: checked(Touch, Hold) says so (Hold)
%   until state_touch/0 moves on from Touch; then they are checked again.
memory_facts_hold(KB, Id, Checked) :-
    touched(T),
    (   arg(1, Checked, T)
    ->  arg(2, Checked, true)
    ;   (   \+ ( plan_memory_fact_(Id, Goal, Percept, When),
                 \+ ( memory_fact(KB, Goal, Percept1, When1),
                      Percept1 == Percept, When1 == When ) )
        ->  Hold = true
        ;   Hold = false
        ),
        nb_setarg(2, Checked, Hold),     % Hold first: an interrupt between the two
        nb_setarg(1, Checked, T),        % writes leaves the plan to be checked again
        Hold == true
    ).

plan_([], _, [], []).
plan_([F|Fs], Bit, Masks, Facts) :-
    (   F = stimulus(S)
    ->  Masks = [S-Bit|Masks1], Facts = Facts1
    ;   F = fact(G)
    ->  Masks = Masks1, Facts = [G-Bit|Facts1]
    ;   domain_error(feature, F)
    ),
    Bit1 is Bit << 1,
    plan_(Fs, Bit1, Masks1, Facts1).

%   One Stimulus-Mask pair per ground stimulus (a stimulus declared twice owns both bits);
%   a stimulus that is not ground is never perceived (stimulus_perceived/2 compares with
%   ==), so it has no entry.
stimulus_masks(Pairs, Masks) :-
    include(ground, Pairs, Ground),
    msort(Ground, Sorted),
    merge_masks(Sorted, Masks).

merge_masks([], []).
merge_masks([S-B|Ps], Masks) :-
    (   Ps = [S1-B1|Ps1], S1 == S
    ->  B2 is B \/ B1,
        merge_masks([S-B2|Ps1], Masks)
    ;   Masks = [S-B|Masks1],
        merge_masks(Ps, Masks1)
    ).

%   The memory elements that perceive stimulus S.
perceives(S, Percept) :-
    sense(Sense),
    Percept =.. [Sense, S].
perceives(S, at(S, _)).

%!  state_mark(-Mark) is det.
%!  state_forget(+KB) is det.
%!  state_forget(+KB, +Mark) is det.
%
%   Forget the tables of KB's plans: all of them, or those made before state_mark/1 gave
%   Mark. Their compiled facts go with relrl_rules:rules_forget/1,2.

state_mark(Mark) :-
    flag(relrl_state_plan, Mark, Mark).

state_forget(KB) :-
    state_forget(KB, inf).

state_forget(KB, Mark) :-
    forall(( plan_kb_(Id, KB), Id < Mark ),
           ( retractall(plan_kb_(Id, KB)),
             retractall(plan_stimulus_(Id, _, _)),
             retractall(plan_fact_(Id, _, _, _)),
             retractall(plan_memory_fact_(Id, _, _, _)),
             retractall(plan_reinforcer_(Id, _)) )).

%!  plan_code(+KB, +Plan, -Code:integer) is det.
%!  plan_code(+KB, +Plan, -Code:integer, -Reinforced) is det.
%!  plan_code(+KB, +Record, +Plan, -Code:integer, -Reinforced) is det.
%
%   Code is the state code now, by a plan from state_plan/3,4; Reinforced is `true` when a
%   stimulus of the plan's Reinforcers is sensed now (a Sense(S) percept of age 0, Sense
%   one of see, hear, smell, at), else `false`: one pass over working memory for both.
%   Record is KB's record (relrl_kbstate:kb_record/2), for a caller that has it (the
%   control step).

plan_code(KB, Plan, Code) :-
    plan_code(KB, Plan, Code, _).

plan_code(KB, Plan, Code, Reinforced) :-
    kb_record(KB, Record),
    plan_code(KB, Record, Plan, Code, Reinforced).

plan_code(KB, Record, plan(Id, Program, Goals, Checked), Code, Reinforced) :-
    wm_stamped(Record, Clock, Pairs),
    (   memory_facts_hold(KB, Id, Checked)
    ->  scan(Pairs, Id, Clock, true, 0, Code0, false, Reinforced),
        program_mask(Program, Code0, Code)
    ;   scan(Pairs, Id, Clock, false, 0, Code0, false, Reinforced),
        program_mask(Goals, Code0, Code)
    ).

%!  plan_reinforced(+Record, +Plan, -Reinforced) is det.
%
%   Reinforced is what plan_code/5 gives, without the state code: for an engine whose
%   learner never reads the code. Record is the knowledge base's record.

plan_reinforced(Record, plan(Id, _, _, _), Reinforced) :-
    wm_stamped(Record, Clock, Pairs),
    (   member(E-Stamp, Pairs),
        Stamp =:= Clock,
        plan_reinforcer_(Id, E)
    ->  Reinforced = true
    ;   Reinforced = false
    ).

%   The pass over memory: the bits of the stimuli each element perceives and (Facts ==
%   true) of the memory facts it makes true, and whether a reinforcer is sensed now (R).
scan([], _, _, _, Mask, Mask, R, R).
scan([E-Stamp|Es], Id, Clock, Facts, Mask0, Mask, R0, R) :-
    (   plan_stimulus_(Id, E, M)
    ->  Mask1 is Mask0 \/ M
    ;   Mask1 = Mask0
    ),
    (   Facts == true,
        plan_fact_(Id, E, Any, Now)
    ->  (   Stamp =:= Clock
        ->  Mask2 is Mask1 \/ Any \/ Now
        ;   Mask2 is Mask1 \/ Any
        )
    ;   Mask2 = Mask1
    ),
    (   R0 == false,
        Stamp =:= Clock,
        plan_reinforcer_(Id, E)
    ->  R1 = true
    ;   R1 = R0
    ),
    scan(Es, Id, Clock, Facts, Mask2, Mask, R1, R).

%!  state_decode(+KB, +Code, -Terms:list) is det.
%
%   Terms are the features whose bits are set in Code.
%
%   @error type_error(nonneg, Code) if Code is not a non-negative integer.
%   @error domain_error(state_code, Code) if Code has a bit no feature of KB owns.

state_decode(KB, Code, Terms) :-
    must_be(nonneg, Code),
    state_features(KB, Features),
    length(Features, N),
    (   Code >> N =:= 0
    ->  true
    ;   domain_error(state_code, Code)
    ),
    findall(T, ( nth0(X, Features, T), Code /\ (1 << X) =\= 0 ), Terms).

%!  state_encode(+KB, +Terms:list, -Code) is det.
%
%   Code is the state code of the features in Terms.
%
%   @error existence_error(feature, T) if a term is not a declared feature.

state_encode(KB, Terms, Code) :-
    must_be(list, Terms),
    state_features(KB, Features),
    foldl(encode_term(Features), Terms, 0, Code).

encode_term(Features, T, Code0, Code) :-
    (   nth0(X, Features, T)
    ->  Code is Code0 \/ (1 << X)
    ;   existence_error(feature, T)
    ).
