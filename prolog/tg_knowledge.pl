:- module(relrl_tg_knowledge,
          [ tg_explain/4,         % +KB, +Facts, +Necessity, -Explanation
            tg_text/2,            % +KB, -Text
            tg_text/3,            % +KB, +Face, -Text
            tg_graph/2,           % +KB, -Graph
            tg_graph/3,           % +KB, +Face, -Graph
            tg_leaf_clauses/2,    % +KB, -Clauses
            tg_leaf_clauses/3,    % +KB, +Face, -Clauses
            tg_save/2,            % +KB, +Stream
            tg_save/3,            % +KB, +Face, +Stream
            tg_policy_term/1,     % ?Term
            tg_restore/2,         % +KB, +Terms
            tg_restore/3,         % +KB, +Face, +Terms
            tg_face/2             % ?Name, ?Face
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(pairs)).
:- use_module(library(aggregate)).
:- use_module(library(occurs)).
:- use_module(tg_bias).
:- use_module(tg_tree).
:- use_module(policy, [policy_refuse/3, policy_number/3]).

%   A tg policy holds one tree (tg_tree/1; ptg's P-tree ptg_tree/1 too).
:- multifile relrl_policy:policy_once/1.
relrl_policy:policy_once(tg_tree(_)).
relrl_policy:policy_once(ptg_tree(_)).

/** <module> The TG tree as knowledge a person reads

Explanations (the first-order tests on an example's path with the bindings that made them
true), the tree as indented text and as a graph, the leaves as q/3 rules, and policy files:
written as Prolog that plain swipl consults, read back by relrl as terms (never run).

The same tree code holds other functions than Q (ptg.pl's P-tree, whose leaves estimate
whether an action is optimal): a *face* names what a tree's leaves hold, as the policy file
and the drawings write it — face(TreeName, RuleName, ValueName), tg's face(tg_tree, q, 'Q')
(tg_face/2). The predicates of arity one less use tg's.
*/

%!  tg_face(?Name, ?Face) is nondet.
%
%   Face is face(TreeName, RuleName, ValueName) of a kind of tree: `q` (tg's Q-tree:
%   tg_tree/1 and q/3 rules) or `p` (ptg.pl's P-tree: ptg_tree/1 and p/3 rules).

tg_face(q, face(tg_tree, q, 'Q')).
tg_face(p, face(ptg_tree, p, 'P')).

q_face(Face) :-
    tg_face(q, Face).

% ---- explaining ----------------------------------------------------------------------------

%!  tg_explain(+KB, +Facts, +Necessity, -Explanation) is det.
%
%   Explanation is tg(Ranked): for every response, choice(Action, Q, Leaf, Path) in
%   decreasing Q (ties in declaration order). Path lists the tests from the root to the
%   action's leaf as test(Id, Text, Outcome, Bindings): Text the conjunction with its
%   variables named, Outcome true or false, Bindings the Name=Value pairs of the variables
%   the test introduced, from the first solution of the query that made it true.

tg_explain(KB, Facts, N, tg(Ranked)) :-
    tg_get_tree(KB, tree(Root, _, _, Responses)),
    findall(NegQ-choice(A, Q, Leaf, Path),
            ( member(A, Responses),
              explain_path(Root, [], [], Facts, A, N, Path, Leaf),
              tg_leaf(KB, Leaf, L), arg(1, L, Q),
              NegQ is -Q ),
            Keyed),
    keysort(Keyed, Sorted),
    pairs_values(Sorted, Ranked).

explain_path(leaf(Id, _, _, _), _, _, _, _, _, [], Id).
explain_path(node(Id, Lits, New, Yes, No), Path, Vars, Facts, A, N, [Step|Steps], Leaf) :-
    append(Path, Lits, Path1),
    append(Vars, New, Vars1),
    name_variables(Vars1, Names),
    conj_text(Lits, Names, Text),
    (   \+ \+ holds_all(Path1, Facts, A, N)
    ->  copy_term(Path1-Names, Path2-Names2),
        once(holds_all(Path2, Facts, A, N)),
        include(introduced(New, Names), Names2, Bound0),
        maplist(binding_pair, Bound0, Bound),
        Step = test(Id, Text, true, Bound),
        explain_path(Yes, Path1, Vars1, Facts, A, N, Steps, Leaf)
    ;   Step = test(Id, Text, false, []),
        explain_path(No, Path, Vars, Facts, A, N, Steps, Leaf)
    ).

holds_all(Lits, Facts, A, N) :-
    maplist([L]>>literal_holds(L, Facts, A, N), Lits).

introduced(New, Names, Name=_) :-
    member(Name=V, Names),
    member(W-_, New),
    V == W,
    !.

binding_pair(Name=Value, Name-Value).

% ---- the tree as text, as a graph, as rules ------------------------------------------------

%!  tg_text(+KB, -Text:string) is det.
%
%   Text draws the tree, one line per node, indented by depth.

tg_text(KB, Text) :-
    q_face(Face),
    tg_text(KB, Face, Text).

%!  tg_text(+KB, +Face, -Text:string) is det.
%
%   As tg_text/2, the leaves' values named as Face says (tg_face/2).

tg_text(KB, face(_, _, V), Text) :-
    tg_get_tree(KB, tree(Root, _, _, _)),
    with_output_to(string(Text), text_node(KB, V, Root, [], "", "")).

text_node(KB, V, leaf(Id, _, _, _), _, Indent, Label) :-
    tg_leaf(KB, Id, l(Q, N, _, _, _, _, _, _, _)),
    format("~w~wleaf [~d] ~w=~4f  (n=~d)~n", [Indent, Label, Id, V, Q, N]).
text_node(KB, V, node(Id, Lits, New, Yes, No), Vars, Indent, Label) :-
    append(Vars, New, Vars1),
    name_variables(Vars1, Names),
    conj_text(Lits, Names, Text),
    format("~w~w[~d] ~w ?~n", [Indent, Label, Id, Text]),
    string_concat(Indent, "    ", Deeper),
    text_node(KB, V, Yes, Vars1, Deeper, "yes: "),
    text_node(KB, V, No, Vars, Deeper, "no:  ").

%!  tg_graph(+KB, -Graph) is det.
%
%   Graph is graph(Nodes, Edges): node(Id, test, Label) and node(Id, leaf, Label) (Label a
%   string), edge(From, To, yes) and edge(From, To, no).

tg_graph(KB, Graph) :-
    q_face(Face),
    tg_graph(KB, Face, Graph).

%!  tg_graph(+KB, +Face, -Graph) is det.
%
%   As tg_graph/2, the leaves' values named as Face says (tg_face/2).

tg_graph(KB, face(_, _, V), graph(Nodes, Edges)) :-
    tg_get_tree(KB, tree(Root, _, _, _)),
    graph_node(KB, V, Root, [], Nodes, [], Edges, []).

graph_node(KB, V, leaf(Id, _, _, _), _, [node(Id, leaf, Label)|Ns], Ns, Es, Es) :-
    tg_leaf(KB, Id, l(Q, N, _, _, _, _, _, _, _)),
    format(string(Label), "~w=~2f (n=~d)", [V, Q, N]).
graph_node(KB, V, node(Id, Lits, New, Yes, No), Vars, [node(Id, test, Text)|Ns0], Ns,
           [edge(Id, YId, yes), edge(Id, NId, no)|Es0], Es) :-
    append(Vars, New, Vars1),
    name_variables(Vars1, Names),
    conj_text(Lits, Names, Text),
    arg(1, Yes, YId), arg(1, No, NId),
    graph_node(KB, V, Yes, Vars1, Ns0, Ns1, Es0, Es1),
    graph_node(KB, V, No, Vars, Ns1, Ns, Es1, Es).

%!  tg_leaf_clauses(+KB, -Clauses:list) is det.
%
%   One clause per leaf, q(Action, Necessity, Q) :- Body, that a person can read and plain
%   swipl can run in the domain's knowledge base: Body holds the leaf's path query and, for
%   each no-branch on the path, the negation of that test's query (a renamed copy: TILDE's
%   semantics). action(T) becomes the head's action, necessity(T) its necessity; Q is
%   rounded to three decimals. Inside a negation, what the clause already makes true is
%   left out: an action the head fixes, a ground literal of the body, and the part of the
%   negated path query that shares no variable with the test's own literals (the body
%   proves that part, so \+ (Path', Test) is \+ Test' there). A negated equality is
%   written as X \= Y on the arguments that differ. Variables are named by
%   type (P for a place, T for a toy), Action and Necessity in the head; a variable used
%   once is written _.

tg_leaf_clauses(KB, Clauses) :-
    q_face(Face),
    tg_leaf_clauses(KB, Face, Clauses).

%!  tg_leaf_clauses(+KB, +Face, -Clauses:list) is det.
%
%   As tg_leaf_clauses/2, the rules' head named as Face says (tg_face/2): p(Action,
%   Necessity, P) for a P-tree.

tg_leaf_clauses(KB, Face, Clauses) :-
    leaf_rules(KB, Face, short, Rules),
    maplist(named_rule, Rules, Clauses).

named_rule(Rule-Names, Rule) :-
    term_variables(Rule, Vs),
    foldl(occurrences(Rule), Vs, Counts, []),
    maplist(name_var(Counts), Names).

occurrences(Term, V, [V-N|Cs], Cs) :-
    aggregate_all(count, ( sub_term(X, Term), X == V ), N).

name_var(Counts, Name=V) :-
    (   var(V)
    ->  (   member(W-1, Counts), W == V
        ->  V = '$VAR'('_')
        ;   V = '$VAR'(Name)
        )
    ;   true
    ).

%   Rule-Names for every leaf: the rule with its variables, and Name=Var for each. Form
%   `short` leaves out of each negation the path literals the body proves (as written in
%   policy files since relrl 0.1); `full` negates the whole renamed path query, as policy
%   files written before did: both read back.
leaf_rules(KB, Face, Form, Rules) :-
    tg_get_tree(KB, tree(Root, _, _, _)),
    findall(R, leaf_clause(KB, Face-Form, Root, [], [], [], R), Rules).

leaf_clause(KB, face(_, Name, _)-Form, leaf(Id, _, _, _), Pos, Neg, Vars, Clause-Names) :-
    tg_leaf(KB, Id, l(Q0, _, _, _, _, _, _, _, _)),
    Q is round(Q0 * 1000) / 1000.0,
    Head =.. [Name, Action, Necessity, Q],
    foldl(positive(Action, Necessity), Pos, Goals0, []),
    pairs_keys_values(Neg, NegTests, NegVars),
    maplist(negative(Form, Action, Necessity, Goals0), NegTests, NegGoals),
    append(Goals0, NegGoals, Goals),
    append([Vars|NegVars], AllVars),
    name_variables(AllVars, Names0),
    Names = ['Action'=Action, 'Necessity'=Necessity|Names0],
    (   Goals == []
    ->  Clause = Head
    ;   list_conj_(Goals, Body),
        Clause = (Head :- Body)
    ).
leaf_clause(KB, FF, node(_, Lits, New, Yes, No), Pos, Neg, Vars, Clause) :-
    append(Pos, Lits, Pos1),
    append(Vars, New, Vars1),
    (   leaf_clause(KB, FF, Yes, Pos1, Neg, Vars1, Clause)
    ;   copy_term(Pos-Lits-Vars1, PathCopy-TestCopy-TestVars),
        append(Neg, [(PathCopy-TestCopy)-TestVars], Neg1),
        leaf_clause(KB, FF, No, Pos, Neg1, Vars, Clause)
    ).

positive(A, _, action(T), Gs, Gs) :- !, A = T.
positive(_, N, necessity(T), Gs, Gs) :- !, N = T.
positive(_, _, L, [L|Gs], Gs).

%   The negation of a test's query, Path-Test renamed (run after the positive goals
%   Known, which prove Path).
negative(Form, A, N, Known, Path-Test, Goal) :-
    maplist(body_literal(A, N), Path, PathGoals0),
    maplist(body_literal(A, N), Test, TestGoals),
    (   Form == short
    ->  term_variables(A-N-Known, Outer),
        linked(TestGoals, Outer, PathGoals0, PathGoals)
    ;   PathGoals = PathGoals0
    ),
    append(PathGoals, TestGoals, Goals0),
    exclude(known_true(Known), Goals0, Goals),
    (   Goals == []
    ->  Goal = fail                        % the query holds whenever Known does
    ;   Goals = [X = Y]
    ->  differing(X, Y, X1, Y1),
        Goal = (X1 \= Y1)
    ;   list_conj_(Goals, Conj),
        Goal = (\+ Conj)
    ).

%   linked(+Goals, +Outer, +Candidates, -Linked): the Candidates that share, directly or
%   through other candidates, a variable not in Outer with Goals.
linked(Goals, Outer, Candidates, Linked) :-
    local_vars(Goals, Outer, Vs),
    linked_(Candidates, Vs, Outer, Linked).

linked_(Candidates, Vs, Outer, Linked) :-
    partition(shares(Vs), Candidates, In, Out),
    (   In == []
    ->  Linked = []
    ;   local_vars(In, Outer, Vs1),
        append(Vs, Vs1, Vs2),
        linked_(Out, Vs2, Outer, Linked0),
        append(In, Linked0, Linked)
    ).

local_vars(Term, Outer, Vs) :-
    term_variables(Term, Vs0),
    exclude(in_vars(Outer), Vs0, Vs).

shares(Vs, G) :-
    term_variables(G, Gs),
    member(V, Gs),
    in_vars(Vs, V),
    !.

in_vars(Vs, V) :-
    member(W, Vs),
    W == V,
    !.

body_literal(A, _, action(T), A = T) :- !.
body_literal(_, N, necessity(T), N = T) :- !.
body_literal(_, _, L, L).

known_true(_, X = Y) :-
    X == Y,
    !.
known_true(Known, G) :-
    ground(G),
    member(K, Known),
    K == G,
    !.

%   f(..., X, ...) \= f(..., Y, ...) is X \= Y when every other argument is the same.
differing(X, Y, X1, Y1) :-
    (   compound(X), compound(Y),
        X =.. [F|As], Y =.. [F|Bs],
        same_length(As, Bs),
        one_differs(As, Bs, A, B)
    ->  differing(A, B, X1, Y1)
    ;   X1 = X, Y1 = Y
    ).

one_differs([A|As], [B|Bs], X, Y) :-
    (   A == B
    ->  one_differs(As, Bs, X, Y)
    ;   As == Bs,
        X = A, Y = B
    ).

list_conj_([G], G) :- !.
list_conj_([G|Gs], (G, C)) :- list_conj_(Gs, C).

% ---- saving and restoring ------------------------------------------------------------------

%!  tg_save(+KB, +Stream) is det.
%
%   Write the learned tree to Stream: tg_tree/1 (the tree itself, read back by relrl) and
%   the leaves as q/3 rules (for a person, and for plain swipl).

tg_save(KB, S) :-
    q_face(Face),
    tg_save(KB, Face, S).

%!  tg_save(+KB, +Face, +Stream) is det.
%
%   As tg_save/2, the tree and its rules named as Face says (tg_face/2): a P-tree as
%   ptg_tree/1 and p/3 rules.

tg_save(KB, Face, S) :-
    Face = face(TreeName, _, _),
    tg_get_tree(KB, tree(Root, _, _, _)),
    saved_tree(KB, Root, [], Saved, Vars),
    name_variables(Vars, Names),
    maplist([Name=V]>>(V = '$VAR'(Name)), Names),
    save_comments(TreeName, Lines, RuleLines),
    forall(member(L, Lines), format(S, "% ~w~n", [L])),
    Tree =.. [TreeName, Saved],
    portray_clause(S, Tree),
    nl(S),
    forall(member(L, RuleLines), format(S, "% ~w~n", [L])),
    tg_leaf_clauses(KB, Face, Clauses),
    forall(member(C, Clauses), portray_clause(S, C)).

%   The comment lines a policy file writes above a tree and above its rules.
save_comments(tg_tree,
              ["The tree: tests (conjunctions; a variable is used only in the yes-branch of",
               "the test that introduces it) and leaves (Q estimate, examples counted)."],
              ["The same knowledge as rules: Q of an action in the state working memory",
               "holds now, under the active necessity (one clause per leaf)."]).
save_comments(ptg_tree,
              ["The P-tree: the same kind of tests, and leaves (P: the share of the examples",
               "there that the Q-tree found optimal, examples counted)."],
              ["The policy as rules: P of an action in the state working memory holds now",
               "(near 1: optimal, near 0: not; one clause per leaf)."]).

saved_tree(KB, leaf(Id, _, _, _), _, leaf(Id, Q, N), []) :-
    tg_leaf(KB, Id, l(Q, N, _, _, _, _, _, _, _)).
saved_tree(KB, node(Id, Lits, New, Y, N), Vars, node(Id, Lits, New, SY, SN), All) :-
    append(Vars, New, Vars1),
    saved_tree(KB, Y, Vars1, SY, AY),
    saved_tree(KB, N, Vars, SN, AN),
    append([New, AY, AN], All).

%!  tg_policy_term(?Term) is semidet.
%
%   Term may appear in a tg policy file: tg_tree/1 or a q/3 clause.

tg_policy_term(Term) :-
    nonvar(Term),
    (   Term = tg_tree(_)
    ->  true
    ;   Term = (q(_, _, _) :- _)
    ->  true
    ;   Term = q(_, _, _)
    ).

%!  tg_restore(+KB, +Terms:list) is det.
%
%   Rebuild KB's tree from the terms of a policy file (tg_tree/1; the q/3 rules must be
%   the ones the tree gives). Candidates and their statistics start afresh.
%
%   @error existence_error(tg_tree, Terms) if there is no tg_tree/1 term.
%   @error domain_error(tg_tree, Node) for a malformed node.
%   @error domain_error(tg_rules_match_tree, Clause) for a q/3 rule the tree does not give.

tg_restore(KB, Terms) :-
    q_face(Face),
    tg_restore(KB, Face, Terms).

%!  tg_restore(+KB, +Face, +Terms:list) is det.
%
%   As tg_restore/2, for the tree and rules named as Face says (tg_face/2): a P-tree from
%   ptg_tree/1 and p/3 rules.

tg_restore(KB, Face, Terms) :-
    Face = face(TreeName, _, _),
    Wanted =.. [TreeName, Saved],
    (   memberchk(Wanted, Terms)
    ->  true
    ;   existence_error(TreeName, Terms)
    ),
    tg_get_tree(KB, tree(_, _, Bias, Responses)),
    tg_data(KB, D),
    arg(1, D, Params),
    arg(10, Params, Keep),
    restored(Saved, b(Bias, Keep), [], [], Root, Stats),
    pairs_keys(Stats, Ids),
    (   sort(Ids, Unique), length(Unique, U), length(Ids, U)
    ->  true
    ;   domain_error(tg_tree_unique_ids, Ids)
    ),
    max_list(Ids, MaxId),
    (   MaxId =< U                                   % ids 1 .. U, as the learner numbers
    ->  true
    ;   policy_refuse(Wanted, "node id ~d is out of range: the tree has ~d nodes, ids 1 \c
                              to ~d", [MaxId, U, U])
    ),
    Cap is max(16, MaxId),
    tg_empty_leaves(Cap, Leaves),
    foldl(place_leaf(Leaves), Stats, _, _),
    nb_setarg(2, D, Leaves),
    nb_setarg(3, D, none),
    arg(4, D, Version0), Version is Version0 + 1, nb_setarg(4, D, Version),
    nb_setarg(5, D, 0),
    Next is MaxId + 1,
    tg_put_tree(KB, tree(Root, Next, Bias, Responses)),
    tg_forget_leaves(KB),
    forall(tg_tree_leaf(Root, Leaf), tg_compile_leaf(KB, Leaf)),
    tg_compile_tree(KB, Root),
    check_rules(KB, Face, Terms).

restored(leaf(Id, Q, N), b(Bias, Keep), Path, Vars, leaf(Id, Path, Vars, Cands), [Id-L]) :-
    !,
    (   integer(Id), Id > 0, number(Q), integer(N), N >= 0
    ->  true
    ;   domain_error(tg_tree, leaf(Id, Q, N))
    ),
    restored_number(leaf(Id, Q, N), "Q", Q),
    restored_number(leaf(Id, Q, N), "example count", N),
    refinements(Bias, Path, Vars, Cands),
    length(Cands, K),
    tg_new_stats(Q, N, K, 0, Keep, L).
restored(node(Id, Lits, New, Y, N), B, Path, Vars, node(Id, Lits, New, RY, RN), Stats) :-
    B = b(Bias, _),
    !,
    (   integer(Id), Id > 0, is_list(Lits), Lits \== [], maplist(callable, Lits),
        is_list(New), maplist(typed_var, New)
    ->  true
    ;   domain_error(tg_tree, node(Id, Lits, New))
    ),
    (   member(Lit, Lits), \+ bias_literal(Bias, Lit)
    ->  policy_refuse(node(Id, Lits, New, Y, N), "node ~d: ~q is not a literal of the \c
                      domain's language bias (rmode/1)", [Id, Lit])
    ;   true
    ),
    append(Path, Lits, Path1),
    append(Vars, New, Vars1),
    restored(Y, B, Path1, Vars1, RY, SY),
    restored(N, B, Path, Vars, RN, SN),
    append([Id-test|SY], SN, Stats).
restored(Other, _, _, _, _, _) :-
    domain_error(tg_tree, Other).

%   Lit has the shape of one of the bias's modes (a variable or a constant where the mode
%   has +T, -T or #T): a literal of the domain's relations, action/1 or necessity/1.
bias_literal(bias(Modes, _), Lit) :-
    member(Mode, Modes),
    mode_shape(Mode, Lit),
    !.

mode_shape(Mode, X) :-
    (   Mode =.. [Marker, Type], memberchk(Marker, [+, -, #]), atom(Type)
    ->  ( var(X) -> true ; atomic(X) )
    ;   compound(Mode)
    ->  compound(X),
        compound_name_arguments(Mode, F, Ms),
        compound_name_arguments(X, F, Xs),
        maplist(mode_shape, Ms, Xs)
    ;   X == Mode
    ).

%   A learned number of a leaf read from a policy (policy_number/3 says which are sane).
restored_number(Leaf, What, X) :-
    arg(1, Leaf, Id),
    format(string(Text), "leaf ~d: ~w", [Id, What]),
    policy_number(Leaf, Text, X).

place_leaf(Leaves, Id-L, _, _) :-
    (   L == test
    ->  true
    ;   setarg(Id, Leaves, L)
    ).

typed_var(V-T) :-
    var(V),
    atom(T).

%   The q/3 rules of a policy are the tree written as rules: refuse a file whose rules
%   say something else (an edited rule would otherwise be silently ignored).
check_rules(KB, Face, Terms) :-
    Face = face(_, Name, _),
    leaf_rules(KB, Face, short, Short),
    leaf_rules(KB, Face, full, Full),
    append(Short, Full, Mine),
    include(is_rule(Name), Terms, Rules),
    forall(member(R, Rules),
           (   member(M-_, Mine), same_rule(R, M)
           ->  true
           ;   domain_error(tg_rules_match_tree, R)
           )).

is_rule(Name, Term) :-
    (   Term = (Head :- _)
    ->  true
    ;   Head = Term
    ),
    compound(Head),
    compound_name_arity(Head, Name, 3).

same_rule(R, M) :-
    rule_parts(R, H, B),
    rule_parts(M, H1, B1),
    H =.. [Name, A, N, Q],
    H1 =.. [Name, A1, N1, Q1],
    number(Q),
    abs(Q - Q1) =< 0.0011,
    q(A, N)-B =@= q(A1, N1)-B1.

rule_parts((H :- B), H, B) :- !.
rule_parts(H, H, true).

