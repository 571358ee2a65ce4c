:- module(relrl_state,
          [ state_features/2,     % +KB, -Features
            feature_code/3,       % +KB, ?Term, ?X
            feature_active/2,     % +KB, +Feature
            state_terms/2,        % +KB, -Terms
            state_code/2,         % +KB, -Code
            features_code/3,      % +KB, +Features, -Code
            state_plan/3,         % +KB, +Features, -Plan
            plan_code/3,          % +KB, +Plan, -Code
            plan_code/5,          % +KB, +Plan, +Reinforcers, -Code, -Reinforced
            state_decode/3,       % +KB, +Code, -Terms
            state_encode/3        % +KB, +Terms, -Code
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(declarations).
:- use_module(perception).
:- use_module(rules).
:- use_module(memory).
:- set_prolog_flag(optimise, true).   % arithmetic compiled inline (this file only)

/** <module> The state code

Section 3.1: every declared stimulus and fact is associated with a number x in 0..n-1, and
the state of the environment is the sum of 2^x over the stimuli and facts that hold now.
x follows declaration order, stimuli first and then facts, so a domain file always gives
the same codes. A code decodes back to its terms without loss.

A stimulus holds when it is perceived through any sense (perception.pl); a fact holds when
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
%
%   Plan computes the code of Features (a list from state_features/2) with plan_code/3:
%   the same code as features_code/3, for less work. The stimuli are read off working
%   memory in one pass (memory elements indexed to the stimuli's bits: a stimulus holds
%   when perceived, whatever rules say); each fact is still its goal, run by its rules
%   (relrl_rules:rules_program/4: errors and time limits propagate as under rule_holds/2).
%   Making a plan replaces KB's previous one.

state_plan(KB, Features, plan(Masks, Program)) :-
    must_be(atom, KB),
    must_be(list, Features),
    plan_(Features, 1, Masks0, Facts),
    stimulus_masks(Masks0, Masks),
    rules_program(KB, state_code, Facts, Program).

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

%!  plan_code(+KB, +Plan, -Code:integer) is det.
%
%   Code is the state code now, by a plan from state_plan/3.

plan_code(KB, plan(Masks, Program), Code) :-
    (   Masks == []
    ->  Code0 = 0
    ;   wm_scan(KB, Masks, [], Code0, _)
    ),
    program_mask(Program, Code0, Code).

%!  plan_code(+KB, +Plan, +Reinforcers:list, -Code, -Reinforced) is det.
%
%   plan_code/3, and Reinforced (true or false) as wm_scan/5 gives it for Reinforcers, from
%   the same pass over working memory.

plan_code(KB, plan(Masks, Program), Reinforcers, Code, Reinforced) :-
    wm_scan(KB, Masks, Reinforcers, Code0, Reinforced),
    program_mask(Program, Code0, Code).

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
