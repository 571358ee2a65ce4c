:- module(relrl_contingency,
          [ contingency_init/1,     % +KB
            contingency_choose/6,   % +KB, +Code, +N, +Allowed, +Params, -Action
            contingency_update/6,   % +KB, +Code0, +A0, +N0, +Reinforced, +Params
            contingency_probabilities/6, % +KB, +Code, +N, +Allowed, +Params, -Pairs
            contingency_rules/2,    % +KB, -Rules
            contingency_restore/2,  % +KB, +Rules
            contingency_explain/4,  % +KB, +Code, +N, -Explanation
            contingency_size/2      % +KB, -Size
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(random)).
:- use_module(library(pairs)).
:- use_module(library(assoc)).
:- use_module(declarations).
:- use_module(engine).
:- use_module(rules).
:- use_module(kbstate).
:- use_module(policy, [policy_refuse/3, policy_number/3]).

/** <module> Contingency learning

Section 4.1 of da Silva & Romero (2012). Behaviour rules are three-term contingencies:
an antecedent (the state), a response, and a consequence (the necessity the response
satisfies), with a fitness. A response is chosen by roulette-wheel selection over the
responses allowed now: a response's slice is the summed fitness of the rules that match the
state and the active necessity, or the default fitness when no rule matches (with
`default_always` 1: the default fitness plus the rules' fitness, every response keeping
its default slice).

After the response, its rules learn from the consequence perceived in the next time unit
(consequence_delta/4): when the reinforcer came (the rule satisfied the active necessity)
the fitness rises by the influence rate; when it did not, it falls by `extinction` times the
rate; with `satiation` 1, a reinforcer that came when no necessity was active (the rule
satisfied an inactive necessity) lowers it. Fitness stays within [min_fitness,
max_fitness]. If no rule matched the emitted response, a new rule (state(Code), Response,
Necessity) is stored with the default fitness moved the same way.

Authored rules come from the domain (behaviour/4, with any goal as antecedent) and are
copied here when the learner starts, so their fitness can learn too. Learned rules have the
antecedent state(Code), true when the current state code is Code.

Params: default_fitness, influence, min_fitness, max_fitness, default_always, extinction,
satiation (all numbers; the readings of the paper behind each are in docs/engine.md).
*/

%   ---- The learner's state ------------------------------------------------------------------
%
%   The rules are the `learner` part of the knowledge base's record (kbstate.pl), one term
%   changed in place (nb_setarg/3), so that a step asserts and retracts nothing:
%
%     rules(Authored, Learned, Matched)
%       Authored  a list of a(Id, Antecedent, Response, Necessity, Fitness), in Id order
%       Learned   an assoc from k(Code, Necessity) to rs(Pairs), Pairs Response-f(Fitnesses)
%                 in the order learned: the fitness of each learned rule of that state,
%                 necessity and response, oldest first (one rule unless a response other
%                 than the chosen one was emitted and learned from twice). A choice looks
%                 its state and necessity up once, then each response in a short list.
%       Matched   the rules the last choice used: learned(Code, N, R) and authored(Id)
%                 keys, or [] (none, or already learned from)
%
%   A fitness changes in place in its a/5 or f/1 term; a new learned rule extends its rs/1
%   list (a short copy), or, in a state and necessity new to the learner, puts a new assoc
%   (a copy: nb_setarg/3); the last choice's matches replace the old ones (a short list).

param(Params, Name, Value) :-
    memberchk(Name=Value, Params).

%   KB's rules term (the stored term itself), made empty if the learner part holds none.
rules(KB, Rules) :-
    kb_record(KB, Record),
    record_get(Record, learner, Rules0),
    (   Rules0 = rules(_, _, _)
    ->  Rules = Rules0
    ;   empty_assoc(Empty),
        record_set(Record, learner, rules([], Empty, [])),
        record_get(Record, learner, Rules)
    ).

set_rules(KB, Authored, Learned) :-
    kb_set(KB, learner, rules(Authored, Learned, [])).

%!  contingency_init(+KB) is det.
%
%   Forget learned rules; copy the domain's authored behaviour rules.

contingency_init(KB) :-
    must_be(atom, KB),
    findall(rule(A, R, N, F), behaviour_rule(KB, A, R, N, F), Rules),
    findall(a(Id, A, R, N, F), nth1(Id, Rules, rule(A, R, N, F)), Authored),
    empty_assoc(Learned),
    set_rules(KB, Authored, Learned).

%!  contingency_choose(+KB, +Code, +N, +Allowed, +Params, -Action) is det.
%
%   Roulette-wheel selection over Allowed in the state Code under necessity N.

contingency_choose(KB, Code, N, Allowed, Params, Action) :-
    Allowed \== [],
    rules(KB, Rules),
    slices(KB, Rules, Code, N, Allowed, Params, Slices, Total),
    random(X0),
    X is X0 * Total,
    pick(Slices, X, slice(Action, _, Matches)),
    nb_setarg(3, Rules, Matches).

%!  contingency_probabilities(+KB, +Code, +N, +Allowed, +Params, -Pairs) is det.
%
%   Pairs is Response-Probability for each response of Allowed: the probability that
%   contingency_choose/6 picks it in the state Code under necessity N (its slice of the
%   wheel over the whole wheel).

contingency_probabilities(KB, Code, N, Allowed, Params, Pairs) :-
    must_be(list, Allowed),
    rules(KB, Rules),
    slices(KB, Rules, Code, N, Allowed, Params, Slices, Total),
    findall(R-P, ( member(slice(R, F, _), Slices), P is F / Total ), Pairs).

slices(KB, rules(Authored, Learned, _), Code, N, Allowed, Params, Slices, Total) :-
    param(Params, default_fitness, Default),
    param(Params, default_always, Always),
    here(Learned, Code, N, Here),
    maplist(slice(KB, Authored, Here, Code, N, Default, Always), Allowed, Slices),
    sum_list_of(Slices, Total).

%   A response's slice: its matching rules' fitness, or the default without one; with
%   default_always the default stays in every slice and the rules' fitness is added to it.
slice(KB, Authored, Here, Code, N, Default, Always, R, slice(R, F, Matches)) :-
    matching_rules(KB, Authored, Here, Code, N, R, Pairs),
    pairs_keys_values(Pairs, Matches, Fs),
    sum_list(Fs, F0),
    (   Always =:= 0
    ->  (   Pairs == []
        ->  F = Default
        ;   F = F0
        )
    ;   F is Default + F0
    ).

%   Here: the learned rules of the state Code and the necessity N (rs/1's pairs).
here(Learned, Code, N, Here) :-
    (   get_assoc(k(Code, N), Learned, rs(Here0))
    ->  Here = Here0
    ;   Here = []
    ).

%   Pairs are Rule-Fitness for the rules of response R that match the state Code and the
%   necessity N: the learned ones (Here), then the authored ones whose antecedent holds, in
%   their order.
matching_rules(KB, Authored, Here, Code, N, R, Pairs) :-
    (   memberchk(R-f(Fs), Here)
    ->  learned_pairs(Fs, learned(Code, N, R), Pairs, Rest)
    ;   Pairs = Rest
    ),
    authored_pairs(Authored, KB, N, R, Rest).

learned_pairs([], _, Pairs, Pairs).
learned_pairs([F|Fs], Key, [Key-F|Pairs], Rest) :-
    learned_pairs(Fs, Key, Pairs, Rest).

authored_pairs([], _, _, _, []).
authored_pairs([a(Id, Antecedent0, R0, N1, F)|As], KB, N, R, Pairs) :-
    (   N1 == N,
        R0 = R,
        copy_term(Antecedent0, Antecedent),   % the stored rule keeps its variables
        rule_holds(KB, Antecedent)
    ->  Pairs = [authored(Id)-F|Pairs1]
    ;   Pairs = Pairs1
    ),
    authored_pairs(As, KB, N, R, Pairs1).

sum_list_of(Slices, Total) :-
    foldl(add_slice, Slices, 0, Total).

add_slice(slice(_, F, _), T0, T) :-
    T is T0 + F.

pick([S], _, S) :- !.
pick([S|Ss], X, Pick) :-
    S = slice(_, F, _),
    (   X < F
    ->  Pick = S
    ;   X1 is X - F,
        pick(Ss, X1, Pick)
    ).

%!  contingency_update(+KB, +Code0, +A0, +N0, +Reinforced, +Params) is det.
%
%   Learn from the consequence of emitting A0 in state Code0 under necessity N0 (`none`
%   when no necessity was active). Reinforced is true when a reinforcer was perceived in
%   the next time unit. The rules the choice used move by consequence_delta/4; without one,
%   a new rule (state(Code0), A0, N0) is stored, its fitness the default moved by the same
%   amount (with default_always, where the default stays in the slice apart, the amount
%   alone, within the bounds).

contingency_update(KB, Code0, A0, N0, Reinforced, Params) :-
    consequence_delta(Params, N0, Reinforced, Delta),
    rules(KB, Rules),
    Rules = rules(_, Learned0, Matches),
    (   Matches \== []
    ->  nb_setarg(3, Rules, []),
        forall(member(M, Matches), adjust(Rules, M, Delta, Params))
    ;   param(Params, default_fitness, Default),
        param(Params, default_always, Always),
        (   Always =:= 0
        ->  Base = Default
        ;   Base = 0
        ),
        clamp(Params, Base + Delta, F),
        (   add_learned(Learned0, Code0, N0, A0, F)
        ->  true
        ;   put_assoc(k(Code0, N0), Learned0, rs([A0-f([F])]), Learned),
            nb_setarg(2, Rules, Learned)
        )
    ).

%   Add a rule of fitness F to Learned in place; fails when Learned has no rule of the
%   state Code and the necessity N yet.
add_learned(Learned, Code, N, R, F) :-
    get_assoc(k(Code, N), Learned, Cell),
    Cell = rs(Pairs0),
    (   memberchk(R-FCell, Pairs0)
    ->  FCell = f(Fs0),
        append(Fs0, [F], Fs),
        nb_setarg(1, FCell, Fs)
    ;   append(Pairs0, [R-f([F])], Pairs),
        nb_setarg(1, Cell, Pairs)
    ).

%!  consequence_delta(+Params, +N0, +Reinforced, -Delta) is det.
%
%   How much the consequence of a response moves its rules' fitness. A reinforcer raises
%   them by the influence rate (the rule satisfied the active necessity); with `satiation`
%   1, a reinforcer that came when no necessity was active (N0 = none) lowers them instead
%   (the rule satisfied an inactive necessity). No reinforcer lowers them by `extinction`
%   times the influence rate (1: by the rate; 0: a response with no consequence leaves its
%   rules as they are).

consequence_delta(Params, N0, Reinforced, Delta) :-
    param(Params, influence, Rate),
    (   Reinforced == true
    ->  param(Params, satiation, Satiation),
        (   N0 == none, Satiation =\= 0
        ->  Delta is -Rate
        ;   Delta = Rate
        )
    ;   param(Params, extinction, Extinction),
        Delta is -Rate * Extinction
    ).

%   A learned key's first rule moves (and goes last among the key's rules); an authored
%   rule moves in place.
adjust(rules(_, Learned, _), learned(Code, N, R), Delta, Params) :-
    (   get_assoc(k(Code, N), Learned, rs(Pairs)),
        memberchk(R-Cell, Pairs),
        Cell = f([F0|Fs])
    ->  clamp(Params, F0 + Delta, F),
        append(Fs, [F], Fs1),
        nb_setarg(1, Cell, Fs1)
    ;   true
    ).
adjust(rules(Authored, _, _), authored(Id), Delta, Params) :-
    (   member(Rule, Authored),
        arg(1, Rule, Id)
    ->  arg(5, Rule, F0),
        clamp(Params, F0 + Delta, F),
        nb_setarg(5, Rule, F)
    ;   true
    ).

clamp(Params, Expr, F) :-
    param(Params, min_fitness, Min),
    param(Params, max_fitness, Max),
    F is min(Max, max(Min, Expr)).

%!  contingency_rules(+KB, -Rules:list) is det.
%
%   Rules are behaviour(Antecedent, Response, Necessity, Fitness) terms, authored first (in
%   the domain's order), then the learned ones by state code and necessity (and, within
%   those, in the order learned).

contingency_rules(KB, Rules) :-
    rules(KB, rules(Authored0, Learned0, _)),
    findall(behaviour(A, R, N, F), member(a(_, A, R, N, F), Authored0), Authored),
    assoc_to_list(Learned0, Pairs),
    findall(behaviour(state(C), R, N, F),
            ( member(k(C, N)-rs(RFs), Pairs), member(R-f(Fs), RFs), member(F, Fs) ),
            Learned),
    append(Authored, Learned, Rules).

%!  contingency_restore(+KB, +Rules:list) is det.
%
%   Replace KB's rules by Rules, behaviour(Antecedent, Response, Necessity, Fitness) terms
%   as listed by contingency_rules/2.

contingency_restore(KB, Rules) :-
    must_be(list, Rules),
    findall(a(Id, A, R, N, F),
            ( nth1(Id, Rules, behaviour(A, R, N, F)), \+ learned_rule(A) ), Authored),
    findall(l(Code, N, R, F), member(behaviour(state(Code), R, N, F), Rules), Keyed0),
    include(learned_key, Keyed0, Keyed),
    empty_assoc(Empty),
    foldl(restore_learned, Keyed, Empty, Learned),
    set_rules(KB, Authored, Learned).

learned_rule(A) :-
    nonvar(A),
    A = state(Code),
    integer(Code).

learned_key(l(Code, _, _, _)) :-
    integer(Code).

restore_learned(l(Code, N, R, F), Learned0, Learned) :-
    (   add_learned(Learned0, Code, N, R, F)
    ->  Learned = Learned0
    ;   put_assoc(k(Code, N), Learned0, rs([R-f([F])]), Learned)
    ).

%!  contingency_explain(+KB, +Code, +N, -Explanation) is det.
%
%   Explanation lists, for each response with a matching rule in state Code under N,
%   Response-Fitness, highest first.

contingency_explain(KB, Code, N, Ranked) :-
    rules(KB, rules(Authored, Learned, _)),
    here(Learned, Code, N, Here),
    findall(F-R, ( kb_response(KB, R),
                   matching_rules(KB, Authored, Here, Code, N, R, Pairs0),
                   Pairs0 \== [],
                   pairs_values(Pairs0, Fs),
                   sum_list(Fs, F) ), Pairs),
    sort(1, @>=, Pairs, Sorted),
    findall(R-F, member(F-R, Sorted), Ranked).

%!  contingency_size(+KB, -Size) is det.
%
%   Size is size(Rules, Positions): the number of stored rules; each takes one position.

contingency_size(KB, size(Rules, Rules)) :-
    rules(KB, rules(Authored, Learned, _)),
    length(Authored, A),
    aggregate_all(count, ( gen_assoc(_, Learned, rs(Pairs)), member(_-f(Fs), Pairs),
                           member(_, Fs) ), L),
    Rules is A + L.

%   ---- The engine's hooks (see engine.pl) ------------------------------------------------

relrl_engine:learner(contingency).
relrl_engine:learner_property(contingency, Cap) :-
    member(Cap, [size, text, knowledge, policy, snapshot]).

%   Parameters (learners.pl; their reading of section 4.1 in docs/engine.md, "Contingency"):
%   default_fitness (the slice of a response with no matching rule), influence (how much a
%   consequence moves a rule's fitness), min_fitness and max_fitness (0 < min_fitness =<
%   default_fitness =< max_fitness), default_always (1: every response keeps the default
%   slice, its rules' fitness added to it), extinction (how much of the influence rate a
%   response followed by no reinforcer loses), satiation (1: a reinforcer that comes when no
%   necessity is active lowers the rule). The defaults are the fixed task's.
relrl_engine:learner_parameter(contingency, default_fitness, 1.0, number).
relrl_engine:learner_parameter(contingency, influence, 0.5, number).
relrl_engine:learner_parameter(contingency, min_fitness, 0.05, number).
relrl_engine:learner_parameter(contingency, max_fitness, 10.0, number).
relrl_engine:learner_parameter(contingency, default_always, 0.0, flag).
relrl_engine:learner_parameter(contingency, extinction, 1.0, unit).
relrl_engine:learner_parameter(contingency, satiation, 0.0, flag).
relrl_engine:learner_serves(contingency, domains, []).

relrl_engine:learner_forget(contingency, _KB).     % all in the record

relrl_engine:learner_init(contingency, KB, _Params) :-
    contingency_init(KB).

relrl_engine:learner_choose(contingency, KB, Code, N, Allowed, _Mode, Action) :-
    engine_params(KB, Params),
    contingency_choose(KB, Code, N, Allowed, Params, Action).

relrl_engine:learner_update(contingency, KB, transition(Code0, A0, N0, _, _, Reinforced, _, _, _)) :-
    engine_params(KB, Params),
    contingency_update(KB, Code0, A0, N0, Reinforced, Params).

relrl_engine:learner_explain(contingency, KB, Code, N, contingency(Ranked)) :-
    contingency_explain(KB, Code, N, Ranked).

relrl_engine:learner_size(contingency, KB, size(Positions, [rules=Rules])) :-
    contingency_size(KB, size(Rules, Positions)).

relrl_engine:learner_text(contingency, KB, Text) :-
    contingency_rules(KB, Rules),
    with_output_to(string(Text),
                   forall(member(behaviour(A, R, N, F), Rules),
                          format("~q -> ~q [~q] fitness ~4f~n", [A, R, N, F]))).

relrl_engine:learner_knowledge(contingency, KB, Rules) :-
    contingency_rules(KB, Rules).

relrl_engine:learner_save(contingency, KB, S) :-
    contingency_rules(KB, Rules),
    forall(member(behaviour(A, R, N, F), Rules),
           portray_clause(S, learned_behaviour(A, R, N, F))).

relrl_engine:learner_policy_term(contingency, learned_behaviour(_, _, _, _)).

%   Rebuild the rules from policy terms read as data, checked as a whole before anything
%   changes. A learned rule's antecedent is state(Code), Code a state of the domain's
%   features; any other antecedent must be one the domain itself authored (a policy file
%   never brings a goal of its own to run). Responses and necessities (or none) are the
%   domain's, a fitness is a finite number >= 0, and no rule is given twice.
relrl_engine:learner_restore(contingency, KB, Terms) :-
    engine_config(KB, features, Features),
    length(Features, NF),
    engine_config(KB, responses, Responses),
    engine_config(KB, necessities, Necessities),
    include(is_rule_term, Terms, RuleTerms),       % the terms read, not copies
    maplist(check_rule(KB, NF, Responses, [none|Necessities]), RuleTerms),
    include(is_learned_rule, RuleTerms, Learned),
    map_list_to_pairs(rule_key, Learned, Keyed),
    msort(Keyed, Sorted),
    (   append(_, [K-_, K-Twice|_], Sorted)
    ->  policy_refuse(Twice, "this learned rule is given twice (its fitness would count \c
                             twice)", [])
    ;   true
    ),
    findall(behaviour(A, R, N, F), member(learned_behaviour(A, R, N, F), RuleTerms), Rules),
    contingency_restore(KB, Rules).

is_rule_term(learned_behaviour(_, _, _, _)).

is_learned_rule(learned_behaviour(state(_), _, _, _)).

rule_key(learned_behaviour(A, R, N, _), rule(A, R, N)).

check_rule(KB, NF, Responses, Necessities, T) :-
    T = learned_behaviour(A, R, N, F),
    (   A = state(Code)
    ->  (   integer(Code), Code >= 0, Code < 1 << NF
        ->  true
        ;   policy_refuse(T, "~q is not a state of this domain (its ~d features give codes \c
                              0 to 2^~d - 1)", [A, NF, NF])
        )
    ;   behaviour_rule(KB, A0, R0, N0, _), A0 =@= A, R0 =@= R, N0 =@= N
    ->  true
    ;   policy_refuse(T, "~q is neither state(Code) nor the antecedent of one of the \c
                          domain's behaviour rules for ~q (a policy brings no goal of its \c
                          own)", [A, R])
    ),
    (   member(R1, Responses), R1 =@= R
    ->  true
    ;   policy_refuse(T, "~q is not a response of this domain", [R])
    ),
    (   member(N1, Necessities), N1 == N
    ->  true
    ;   policy_refuse(T, "~q is not a necessity of this domain (nor none)", [N])
    ),
    policy_number(T, "the fitness", F),
    (   F >= 0
    ->  true
    ;   policy_refuse(T, "the fitness ~q is negative (a fitness is a slice of the \c
                          roulette wheel, >= 0)", [F])
    ).

relrl_engine:learner_snapshot(contingency, KB, matched(Matches)) :-
    rules(KB, rules(_, _, Matches)).

relrl_engine:learner_resume(contingency, KB, matched(Matches)) :-
    rules(KB, Rules),
    nb_setarg(3, Rules, Matches).
