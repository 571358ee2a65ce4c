:- module(relrl_etg,
          [ etg_init/2,           % +KB, +Tests
            etg_choose/7,         % +KB, +D, +N, +Allowed, +Params, -Action, -Q
            etg_update/9,         % +KB, +D0, +A0, +N0, +R, +D1, +N1, +Allowed1, +Params
            etg_explain/4,        % +KB, +D, +N, -Explanation
            etg_size/2            % +KB, -Size
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(random)).
:- use_module(qtree).
:- use_module(engine).
:- use_module(declarations).
:- use_module(rules).
:- use_module(kbstate).
:- use_module(policy, [policy_refuse/3, policy_number/3]).
:- set_prolog_flag(optimise, true).   % arithmetic compiled inline (this file only)

/** <module> Economic TG (ETG)

Section 4.2.1 and Algorithms 2 and 3 of da Silva & Romero (2012). The Q-function is a
relational regression tree (qtree.pl) whose internal nodes are first-order tests over the
state; leaves hold (action, Q, necessity) entries in decreasing Q. Only entries whose
necessity is the active one are candidates.

Each step gives one example x = (s, a, Q-hat, n), inserted at once (no look-up table of
examples, unlike TG):

    Q-hat = Q(s, a) + alpha * (r + gamma * max_a' Q(s', a') - Q(s, a))      (Eq. 4)

Algorithm 3 (insertion): sort s down the tree; at a leaf, update the action's Q (or insert
the action with its necessity); at an empty branch (null), generate a leaf there. A state
that reaches an empty branch has no entries yet: every response has Q = q_init.

The paper does not say when a leaf is split, and with a single initial leaf and no split
nothing could ever be told apart. relrl's rule, which keeps the tree economic: a leaf
represents every state that sorts to it and remembers the first (its representative). When
an example from a different state disagrees with the leaf — its temporal-difference error
|r + gamma max Q(s') - Q(s, a)| exceeds `split_threshold` — the leaf is split on the first
test that tells the two states apart, and the example goes on to generate a new leaf on the
empty branch. States whose values agree keep sharing a leaf.

Params is a list of Name=Value with alpha, gamma, epsilon, q_init and split_threshold.
*/

param(Params, Name, Value) :-
    memberchk(Name=Value, Params).

%!  etg_init(+KB, +Tests:list) is det.
%
%   Start KB's tree as a single empty leaf over the candidate Tests.

etg_init(KB, Tests) :-
    qtree_new(KB, Tests).

%!  etg_choose(+KB, +D, +N, +Allowed, +Params, -Action, -Q) is det.
%
%   Choose among the Allowed responses for the state described by D under the active
%   necessity N: with probability epsilon a random one, otherwise one with the largest Q
%   (ties broken at random). Actions with no entry for N have Q = q_init.

etg_choose(KB, D, N, Allowed, Params, Action, Q) :-
    Allowed \== [],
    param(Params, q_init, Q0),
    param(Params, epsilon, Epsilon),
    qtree(KB, Tree),
    choose(Tree, D, N, Allowed, Q0, Epsilon, Action, Q).

%   The predicates below take KB's tree (qtree/2), found once by the caller.
choose(Tree, D, N, Allowed, Q0, Epsilon, Action, Q) :-
    leaf_entries(Tree, D, Entries),
    Allowed = [A1|As],
    entry_q(Entries, A1, N, Q0, Q1),
    scores(As, Entries, N, Q0, Scored1, Q1, Best),
    Scored = [Q1-A1|Scored1],
    (   random_float < Epsilon
    ->  random_element(Scored, Q-Action)
    ;   ties(Scored, Best, Ties),
        random_element(Ties, Q-Action)
    ).

%   random_member/2 of library(random) for a list known to be proper and non-empty: the
%   same draw (random(Length)).
random_element(List, X) :-
    length(List, Len),
    I is random(Len),
    nth0(I, List, X).

%   Q of each allowed action (in order), and the largest.
scores([], _, _, _, [], Best, Best).
scores([A|As], Entries, N, Q0, [Q-A|Ss], Best0, Best) :-
    entry_q(Entries, A, N, Q0, Q),
    (   Q < Best0                       % max/2 would give Best0 itself
    ->  Best1 = Best0
    ;   Best1 is max(Best0, Q)
    ),
    scores(As, Entries, N, Q0, Ss, Best1, Best).

ties([], _, []).
ties([Q-A|Ss], Best, Ties) :-
    (   Q =:= Best
    ->  Ties = [Q-A|Ties1]
    ;   Ties = Ties1
    ),
    ties(Ss, Best, Ties1).

%   The Q of the entry for action A under necessity N (Q0 when there is none).
entry_q([], _, _, Q0, Q0).
entry_q([e(A1, Q1, N1)|Es], A, N, Q0, Q) :-
    (   A1 == A, N1 == N
    ->  Q = Q1
    ;   entry_q(Es, A, N, Q0, Q)
    ).

%   The entries of the state's own leaf; none when it reaches an empty branch (a state
%   the tree has not met: every response then has Q = q_init).
leaf_entries(Tree, D, Entries) :-
    qtree_sort(Tree, D, Where),
    (   Where = leaf(Id)
    ->  qtree_leaf(Tree, Id, _, Entries)
    ;   Entries = []
    ).

%!  etg_update(+KB, +D0, +A0, +N0, +R, +D1, +N1, +Allowed1, +Params) is det.
%
%   Learn from the transition (D0, A0, N0) -> reward R -> (D1, N1), Eq. 4 and Algorithm 3.
%   The max in Eq. 4 runs over the responses Allowed1 in the next state (all entries of
%   the leaf when Allowed1 is []).

etg_update(KB, D0, A0, N0, R, D1, N1, Allowed1, Params) :-
    param(Params, alpha, Alpha),
    param(Params, gamma, Gamma),
    param(Params, q_init, Qinit),
    param(Params, split_threshold, Threshold),
    qtree(KB, Tree),
    update(Tree, D0, A0, N0, R, D1, N1, Allowed1, Alpha, Gamma, Qinit, Threshold).

update(Tree, D0, A0, N0, R, D1, N1, Allowed1, Alpha, Gamma, Qinit, Threshold) :-
    leaf_entries(Tree, D1, Next),
    max_q(Next, N1, Allowed1, Qinit, MaxNext),
    Target is R + Gamma * MaxNext,
    insert_example(Tree, D0, A0, N0, Target, Alpha, Qinit, Threshold).

max_q(Entries, N, Allowed, Qinit, Max) :-
    max_allowed(Entries, N, Allowed, none, Max1),
    (   Max1 == none                    % no entry for N of an allowed action
    ->  Max = Qinit
    ;   Max1 > Qinit                    % max(Max1, Qinit) would be Max1 itself
    ->  Max = Max1
    ;   count_allowed(Entries, N, Allowed, 0, K),
        Allowed \== [], length(Allowed, L), K < L
    ->  Max is max(Max1, Qinit)     % some allowed action is still untried
    ;   Max = Max1
    ).

%   The largest Q among the entries for N of allowed actions (none if there is none). An
%   entry whose Q is below the largest so far cannot change it (max/2 would give the
%   largest so far itself), so neither its action's look-up nor the arithmetic is done:
%   in a leaf kept in decreasing Q that is every entry after the first allowed one.
max_allowed([], _, _, Max, Max).
max_allowed([e(A, Q, N1)|Es], N, Allowed, Max0, Max) :-
    (   N1 == N,
        ( Max0 == none -> true ; \+ Q < Max0 ),
        allowed_or_any(Allowed, A)
    ->  (   Max0 == none
        ->  Max1 = Q
        ;   Max1 is max(Max0, Q)
        )
    ;   Max1 = Max0
    ),
    max_allowed(Es, N, Allowed, Max1, Max).

%   How many entries for N are of allowed actions.
count_allowed([], _, _, K, K).
count_allowed([e(A, _, N1)|Es], N, Allowed, K0, K) :-
    (   N1 == N,
        allowed_or_any(Allowed, A)
    ->  K1 is K0 + 1
    ;   K1 = K0
    ),
    count_allowed(Es, N, Allowed, K1, K).

allowed_or_any([], _) :- !.
allowed_or_any(Allowed, A) :- memberchk(A, Allowed).

insert_example(Tree, D, A, N, Target, Alpha, Qinit, Threshold) :-
    qtree_sort(Tree, D, Where),
    (   Where = null(Parent, Branch)
    ->  Q is Qinit + Alpha * (Target - Qinit),
        qtree_grow(Tree, Parent, Branch, D, [e(A, Q, N)], _)
    ;   Where = leaf(Id),
        qtree_leaf(Tree, Id, Rep0, Entries0),
        entry_q(Entries0, A, N, Qinit, Old),
        Error is Target - Old,
        (   Rep0 \== none,
            Rep0 =\= D,
            abs(Error) > Threshold,
            first_difference(Rep0, D, I)
        ->  qtree_split(Tree, Id, I),
            insert_example(Tree, D, A, N, Target, Alpha, Qinit, Threshold)
        ;   ( Rep0 == none -> Rep = D ; Rep = Rep0 ),
            Q is Old + Alpha * Error,
            qtree_put_entry(Entries0, e(A, Q, N), Entries),
            qtree_set_leaf(Tree, Id, Rep, Entries)
        )
    ).

%!  etg_explain(+KB, +D, +N, -Explanation) is det.
%
%   Explanation is explain(Path, Ranked): the tests from the root to the state's leaf with
%   their outcomes, and the leaf's entries for necessity N in decreasing Q.

etg_explain(KB, D, N, explain(Path, Ranked)) :-
    qtree(KB, Tree),
    qtree_path(Tree, D, Path),
    leaf_entries(Tree, D, Entries),
    include(entry_for(N), Entries, Ranked).

entry_for(N, e(_, _, N1)) :-
    N1 == N.

%!  etg_size(+KB, -Size) is det.
%
%   Size is size(Nodes, Leaves, Entries, Positions) with Positions = Nodes + Entries, the
%   paper's memory measure.

etg_size(KB, size(Nodes, Leaves, Entries, Positions)) :-
    qtree(KB, Tree),
    qtree_size(Tree, Nodes, Leaves, Entries),
    Positions is Nodes + Entries.

%   ---- The engine's hooks (see engine.pl) ------------------------------------------------

%   The candidate tests of KB's tree: the domain's features (stimulus(S), fact(F)) in code
%   order, then its etg_test/1 goals. A state's description is its code with a bit for each
%   extra test above the features' bits.

%   What the hooks read every step, the `learner` part of KB's record (kbstate.pl; the tree
%   is its `tree` part): etg(NF, Extra, Numbers) — NF features, the extra tests Extra as a
%   program of relrl_rules (their bits above the features'; `none` without extra tests),
%   and Numbers = numbers(Alpha, Gamma, Epsilon, Qinit, Threshold) from the parameters (or
%   `params` when one is missing: the hooks then read the list, and fail as etg_choose/7
%   does). A hook finds the record once for both.

config(KB, Config) :-
    kb_record(KB, Record),
    record_get(Record, learner, Config).

config(KB, Config, Tree) :-
    kb_record(KB, Record),
    record_get(Record, learner, Config),
    record_get(Record, tree, Tree).

relrl_engine:learner(etg).
relrl_engine:learner_property(etg, Cap) :-
    member(Cap, [state, size, text, graph, policy]).

%   Parameters (learners.pl): alpha, gamma, epsilon (Eq. 4 and epsilon-greedy choice), q_init
%   (Q of an action a leaf has no entry for), split_threshold (temporal-difference error
%   above which a leaf is split between two states it cannot tell apart).
relrl_engine:learner_parameter(etg, alpha, 0.2, unit).
relrl_engine:learner_parameter(etg, gamma, 0.9, unit).
relrl_engine:learner_parameter(etg, epsilon, 0.05, unit).
relrl_engine:learner_parameter(etg, q_init, 30.0, number).
relrl_engine:learner_parameter(etg, split_threshold, 0.1, number).
relrl_engine:learner_serves(etg, domains, []).

relrl_engine:learner_forget(etg, _KB).         % all in the record (and rules.pl's program)

relrl_engine:learner_init(etg, KB, Params) :-
    engine_config(KB, features, Features),
    findall(G, declared(KB, etg_test(G)), Extra),
    length(Features, NF),
    extra_bits(Extra, NF, ExtraBits),
    (   ExtraBits == []
    ->  ExtraTests = none
    ;   rules_program(KB, ExtraBits, ExtraTests)
    ),
    (   maplist(param(Params), [alpha, gamma, epsilon, q_init, split_threshold],
                [Alpha, Gamma, Epsilon, Qinit, Threshold])
    ->  Numbers = numbers(Alpha, Gamma, Epsilon, Qinit, Threshold)
    ;   Numbers = params
    ),
    kb_set(KB, learner, etg(NF, ExtraTests, Numbers)),
    append(Features, Extra, Tests),
    etg_init(KB, Tests).

extra_bits([], _, []).
extra_bits([G|Gs], I, [G-Bit|Bits]) :-
    Bit is 1 << I,
    I1 is I + 1,
    extra_bits(Gs, I1, Bits).

relrl_engine:learner_state(etg, KB, Code, D) :-
    config(KB, etg(_, ExtraTests, _)),
    (   ExtraTests == none
    ->  D = Code
    ;   program_mask(ExtraTests, Code, D)
    ).

relrl_engine:learner_choose(etg, KB, D, N, Allowed, Mode, Action) :-
    config(KB, etg(_, _, Numbers), Tree),
    (   Numbers = numbers(_, _, Epsilon0, Qinit, _)
    ->  Allowed \== [],
        (   Mode == greedy
        ->  Epsilon = 0
        ;   Epsilon = Epsilon0
        ),
        choose(Tree, D, N, Allowed, Qinit, Epsilon, Action, _)
    ;   engine_params(KB, Params0),
        (   Mode == greedy
        ->  Params = [epsilon=0|Params0]
        ;   Params = Params0
        ),
        etg_choose(KB, D, N, Allowed, Params, Action, _)
    ).

relrl_engine:learner_update(etg, KB, transition(D0, A0, N0, _, R, _, D1, N1, Allowed1)) :-
    config(KB, etg(_, _, Numbers), Tree),
    (   Numbers = numbers(Alpha, Gamma, _, Qinit, Threshold)
    ->  update(Tree, D0, A0, N0, R, D1, N1, Allowed1, Alpha, Gamma, Qinit, Threshold)
    ;   engine_params(KB, Params),
        etg_update(KB, D0, A0, N0, R, D1, N1, Allowed1, Params)
    ).

relrl_engine:learner_explain(etg, KB, D, N, etg(Path, Ranked)) :-
    etg_explain(KB, D, N, explain(Path, Ranked)).

relrl_engine:learner_size(etg, KB, size(Positions, [nodes=Nodes, leaves=Leaves,
                                                    entries=Entries])) :-
    etg_size(KB, size(Nodes, Leaves, Entries, Positions)).

relrl_engine:learner_text(etg, KB, Text) :-
    qtree(KB, Tree),
    qtree_format(Tree, Text).

relrl_engine:learner_graph(etg, KB, Graph) :-
    qtree(KB, Tree),
    qtree_graph(Tree, Graph).

relrl_engine:learner_save(etg, KB, S) :-
    qtree(KB, Tree),
    qtree_tests(Tree, Tests),
    portray_clause(S, etg_tests(Tests)),
    nl(S),
    forall(qtree_node(Tree, Id, Node), portray_clause(S, etg_node(Id, Node))).

relrl_engine:learner_policy_term(etg, etg_tests(_)).
relrl_engine:learner_policy_term(etg, etg_node(_, _)).

%   Rebuild the tree from policy terms read as data, checked as a whole before anything
%   changes (no goal from the file is ever run): the tests must be this domain's; the nodes
%   must form one tree (below); each leaf's representative a state of these tests that
%   sorts to it; each entry a response and a necessity (or none) of the domain with a
%   finite Q. A leaf's entries are put in decreasing Q, as the learner keeps them.
relrl_engine:learner_restore(etg, KB, Terms) :-
    qtree(KB, Tree),
    qtree_tests(Tree, Mine),
    include(is_tests, Terms, TestTerms),          % the terms read, not copies
    (   TestTerms = [TestTerm]
    ->  true
    ;   TestTerms = []
    ->  existence_error(policy_term, etg_tests/1)
    ;   TestTerms = [_, TestTerm|_],
        policy_refuse(TestTerm, "etg_tests/1 is given twice", [])
    ),
    TestTerm = etg_tests(Tests),
    (   Tests =@= Mine
    ->  true
    ;   policy_refuse(TestTerm, "the tests are not this domain's (a policy of another \c
                                 domain?)", [])
    ),
    include(is_node, Terms, NodeTerms),
    check_tree(KB, Mine, TestTerm, NodeTerms, Nodes),
    qtree_restore(KB, Tests, Nodes).

%   The nodes are a tree: ids 0 .. N-1 for N nodes, each once; every branch nil or the id
%   of a node; no branch to the root (0); no node with two parents; every node reached from
%   the root. Reached from the root with one parent each, the nodes hold no cycle. Linear
%   in the size of the policy: nodes are looked up by id in a term of N arguments.
check_tree(KB, Tests, TestTerm, NodeTerms, Nodes) :-
    length(NodeTerms, N),
    (   N > 0
    ->  true
    ;   policy_refuse(TestTerm, "no etg_node/2: a tree has at least its root, node 0", [])
    ),
    functor(ById, nodes, N),
    maplist(place_node(ById, N), NodeTerms),
    TestsTerm =.. [tests|Tests],
    length(Tests, NT),
    engine_config(KB, responses, Responses),
    engine_config(KB, necessities, Necessities),
    functor(Parents, parents, N),
    maplist(check_node(TestsTerm, NT, N, Parents, [none|Necessities], Responses), NodeTerms,
            Nodes),
    functor(Seen, seen, N),
    reach([0-0-0], ById, Seen),
    (   between(1, N, I), arg(I, Seen, S), var(S)
    ->  arg(I, ById, Stray),
        Id is I - 1,
        policy_refuse(Stray, "node ~d cannot be reached from the root (node 0): the nodes \c
                              do not form one tree", [Id])
    ;   true
    ).

place_node(ById, N, T) :-
    T = etg_node(Id, _),
    (   integer(Id), Id >= 0, Id < N
    ->  I is Id + 1,
        arg(I, ById, Slot),
        (   var(Slot)
        ->  Slot = T
        ;   policy_refuse(T, "node ~d is defined twice", [Id])
        )
    ;   Last is N - 1,
        policy_refuse(T, "node id ~q is out of range: this policy has ~d nodes, ids 0 to ~d",
                      [Id, N, Last])
    ).

check_node(Tests, NT, N, Parents, Necessities, Responses, T, Id-Node) :-
    T = etg_node(Id, Node0),
    (   Node0 = test(I, Goal, Yes, No)
    ->  (   integer(I), I >= 0, I < NT
        ->  true
        ;   LastTest is NT - 1,
            policy_refuse(T, "node ~d tests test ~q, but the domain has tests 0 to ~d",
                          [Id, I, LastTest])
        ),
        I1 is I + 1,
        arg(I1, Tests, Test),
        (   Test =@= Goal
        ->  true
        ;   policy_refuse(T, "node ~d: test ~d is ~q in this domain, not ~q",
                          [Id, I, Test, Goal])
        ),
        check_branch(T, Id, N, Parents, yes, Yes),
        check_branch(T, Id, N, Parents, no, No),
        Node = Node0
    ;   Node0 = leaf(Rep, Entries0)
    ->  (   Rep == none
        ->  true
        ;   integer(Rep), Rep >= 0, Rep < 1 << NT
        ->  true
        ;   policy_refuse(T, "leaf ~d: its state ~q is not a state of this domain's ~d tests \c
                              (none, or 0 to 2^~d - 1)", [Id, Rep, NT, NT])
        ),
        (   is_list(Entries0)
        ->  true
        ;   policy_refuse(T, "leaf ~d: its entries are not a list", [Id])
        ),
        maplist(check_entry(T, Id, Necessities, Responses), Entries0),
        map_list_to_pairs(entry_key, Entries0, Keyed),
        (   msort(Keyed, Sorted), append(_, [K-_, K-_|_], Sorted)
        ->  K = A-Nec,
            policy_refuse(T, "leaf ~d holds two entries for ~q under ~q", [Id, A, Nec])
        ;   true
        ),
        sort(2, @>=, Entries0, Entries),
        Node = leaf(Rep, Entries)
    ;   policy_refuse(T, "node ~q is neither test(Index, Test, Yes, No) nor \c
                          leaf(State, Entries)", [Id])
    ).

check_branch(T, Id, N, Parents, Branch, Child) :-
    (   Child == nil
    ->  true
    ;   integer(Child), Child > 0, Child < N
    ->  I is Child + 1,
        arg(I, Parents, Parent),
        (   var(Parent)
        ->  Parent = Id
        ;   policy_refuse(T, "node ~d is reached from node ~d and from node ~d: a node of a \c
                              tree has one parent", [Child, Parent, Id])
        )
    ;   Child == 0
    ->  policy_refuse(T, "node ~d's ~w-branch leads back to the root (a cycle)", [Id, Branch])
    ;   policy_refuse(T, "node ~d's ~w-branch leads to node ~q, which this policy does not \c
                          hold (a dangling branch)", [Id, Branch, Child])
    ).

check_entry(T, Id, Necessities, Responses, E) :-
    (   E = e(A, Q, Nec)
    ->  (   member(R, Responses), R == A
        ->  true
        ;   policy_refuse(T, "leaf ~d: ~q is not a response of this domain", [Id, A])
        ),
        (   member(N1, Necessities), N1 == Nec
        ->  true
        ;   policy_refuse(T, "leaf ~d: ~q is not a necessity of this domain (nor none)",
                          [Id, Nec])
        ),
        format(string(What), "leaf ~d: the Q of ~q", [Id, A]),
        policy_number(T, What, Q)
    ;   policy_refuse(T, "leaf ~d: ~q is not an entry e(Response, Q, Necessity)", [Id, E])
    ).

entry_key(e(A, _, N), A-N).

is_node(etg_node(_, _)).

is_tests(etg_tests(_)).

%   Walk the tree from the root, marking each node reached in Seen: Stack holds Id-Yes-No,
%   the tests known to hold (Yes) and to fail (No) on the way to node Id, as bit masks. A
%   leaf's representative must agree with them (a state that reaches the leaf).
reach([], _, _).
reach([Id-Yes-No|Stack], ById, Seen) :-
    I is Id + 1,
    arg(I, Seen, true),
    arg(I, ById, T),
    T = etg_node(_, Node),
    (   Node = test(Test, _, YesChild, NoChild)
    ->  Bit is 1 << Test,
        Yes1 is Yes \/ Bit,
        No1 is No \/ Bit,
        push(YesChild, Yes1, No, Stack, Stack1),
        push(NoChild, Yes, No1, Stack1, Stack2),
        reach(Stack2, ById, Seen)
    ;   Node = leaf(Rep, _),
        (   Rep == none
        ->  true
        ;   Rep /\ Yes =:= Yes, Rep /\ No =:= 0
        ->  true
        ;   policy_refuse(T, "leaf ~d: its state ~d does not reach it (the tests on the path \c
                              from the root disagree)", [Id, Rep])
        ),
        reach(Stack, ById, Seen)
    ).

push(nil, _, _, Stack, Stack) :- !.
push(Id, Yes, No, Stack, [Id-Yes-No|Stack]).
