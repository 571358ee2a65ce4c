:- module(relrl_tg_bias,
          [ tg_bias/2,            % +KB, -Bias
            refinements/4,        % +Bias, +PathLits, +Vars, -Candidates
            root_refinements/2,   % +KB, -Texts
            literal_goal/6,       % +Literal, +Facts, +Action, +Necessity, +Last, -Goal
            conj_goal/6,          % +Literals, +Facts, +Action, +Necessity, +Bound, -Goal
            query_goal/6,         % +Literals, +Facts, +Action, +Necessity, +Bound, -Goal
            literal_components/2, % +Literals, -Components
            facts_index/2,        % +Facts, -Index
            fact_member/2,        % ?Literal, +Index
            literal_holds/4,      % +Literal, +Facts, +Action, +Necessity
            bias_problem/2,       % +KB, -Problem
            bias_warning/2,       % +KB, -Warning
            bias_constants/2,     % +Bias, -Constants
            term_constant/2,      % +Term, ?Constant
            name_variables/2,     % +Vars, -Names
            conj_text/3           % +Literals, +Names, -Text
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(pairs)).
:- use_module(library(assoc)).
:- use_module(declarations).

/** <module> The language bias of the TG learner

**The relational view.** A domain declares relational percept predicates with relation/1,
a template whose ground solutions, now, are the facts of the relational state:

    relation(gaze(_Who, _Place)).        gaze(face, Place) :- ...   (from working memory)
    relation(toy_at(_Toy, _Place)).

The engine collects them, sorted (engine_relational_state/2): the state TG learns from is a
ground list such as [colour(toy, red), head_at(centre), gaze(face, left), ...]. The 2^x
state code of the other learners is not touched.

**The language bias**, in the style of TILDE/ACE rmode declarations, says which literals a
test may hold:

    rmode(gaze(#agent, -place)).    #T  each constant of type T declared by rconst(T, C)
    rmode(head_at(+place)).         +T  a variable of type T bound earlier on the path
    rmode(toy_at(-toy, +place)).    -T  a new variable of type T, usable only below, in the
    rmode(action(look(-place))).        yes-branch of the test that introduces it
    rconst(agent, face).

Two predicates are not relations: action/1 tests the example's action (the response the
Q-value is for), necessity/1 the active necessity (its constants, type `necessity`, are the
declared necessities and `none`). Arguments may be nested terms whose own arguments carry
modes, as in action(look(-place)).

**The refinement operator** (refinements/4) gives the candidate tests of a leaf whose path
query (the conjunction of the tests on the yes-branches above it) is PathLits, with typed
variables Vars: every literal the bias allows there and, for a literal that introduces new
variables, that literal followed by one more that uses one of them (TILDE's lookahead, here
automatic: a literal that only introduces a variable, such as action(look(P)), changes no
Q-value by itself; action(look(P)), gaze(face, P) may). Candidates that the path already
implies are left out, and conjunctions that differ only in the order of their literals or
the names of their variables are given once.
*/

% ---- the bias ------------------------------------------------------------------------------

%!  tg_bias(+KB, -Bias) is det.
%
%   Bias is bias(Modes, Consts): the rmode/1 literals of KB in declaration order, then the
%   modes extra_rmode/2 adds, and Type-Constants pairs (necessity: the declared necessities
%   and none).

:- multifile extra_rmode/2.

%   extra_rmode(?KB, ?Mode): a mode a driver adds to KB's bias for its run (world.pl: the
%   task_rmode/2 modes of the task the world's learner is configured for).

:- multifile own_rmodes/1.

%   own_rmodes(+KB): for KB's run the driver's extra_rmode/2 modes are the whole bias, KB's
%   rmode/1 left out (world.pl: a task the world declares task_own_bias/1 for). No clause
%   holds for a domain: its bias is its rmode/1.

tg_bias(KB, bias(Modes, Consts)) :-
    (   own_rmodes(KB)
    ->  findall(M, extra_rmode(KB, M), Modes0)
    ;   findall(M, ( declared(KB, rmode(M)) ; extra_rmode(KB, M) ), Modes0)
    ),
    list_to_set(Modes0, Modes),
    findall(T-C, declared(KB, rconst(T, C)), Pairs0),
    findall(necessity-N, ( kb_necessity(KB, N) ; N = none ), Nec),
    append(Pairs0, Nec, Pairs1),
    list_to_set(Pairs1, Pairs),
    group_consts(Pairs, Consts).

group_consts(Pairs, Consts) :-
    pairs_keys(Pairs, Types0),
    list_to_set(Types0, Types),
    findall(T-Cs, ( member(T, Types), findall(C, member(T-C, Pairs), Cs) ), Consts).

%   A literal the bias allows, given the typed variables Vars bound before it; New are
%   the typed variables it introduces.
literal(bias(Modes, Consts), Vars, Lit, New) :-
    member(Mode, Modes),
    instantiate(Mode, Vars, Consts, Lit, [], New0),
    reverse(New0, New).

instantiate(M, Vars, Consts, X, New0, New) :-
    (   M = +(T), atom(T)
    ->  member(V-T, Vars), X = V, New = New0
    ;   M = -(T), atom(T)
    ->  New = [X-T|New0]
    ;   M = #(T), atom(T)
    ->  memberchk(T-Cs, Consts), member(X, Cs), New = New0
    ;   compound(M)
    ->  M =.. [F|Ms],
        foldl(instantiate_arg(Vars, Consts), Ms, Xs, New0, New),
        X =.. [F|Xs]
    ;   X = M, New = New0
    ).

instantiate_arg(Vars, Consts, M, X, New0, New) :-
    instantiate(M, Vars, Consts, X, New0, New).

%!  refinements(+Bias, +PathLits:list, +Vars:list, -Candidates:list) is det.
%
%   Candidates are the candidate tests of a leaf with path query PathLits and typed
%   variables Vars (Var-Type pairs): cand(Literals, New) terms, Literals a conjunction (a
%   list of one or two literals) sharing variables with PathLits, New the Var-Type pairs
%   it introduces. Simpler candidates first, then in bias order.

refinements(Bias, PathLits, Vars, Candidates) :-
    term_variables(PathLits-Vars, PV),
    findall(PV-I-cand(Lits, New),
            ( candidate(Bias, Vars, Lits, New),
              \+ implied(Lits, PathLits, PV),
              length(Lits, I) ),
            Found),
    maplist(rebind(PV), Found, Indexed),
    number_list(Indexed, 0, Numbered),
    map_list_to_pairs(canonical(PV), Numbered, Keyed),
    sort(1, @<, Keyed, Unique),                 % one of each, the first generated
    pairs_values(Unique, Kept),
    sort(1, @=<, Kept, Ordered),                % back to generation order
    pairs_values(Ordered, Candidates0),
    pairs_values(Candidates0, Candidates).

rebind(PV, PV-I-C, I-C).

number_list([], _, []).
number_list([Len-C|Cs], N, [(Len-N)-(Len-C)|Out]) :-
    N1 is N + 1,
    number_list(Cs, N1, Out).

candidate(Bias, Vars, Lits, New) :-
    literal(Bias, Vars, L1, New1),
    (   Lits = [L1], New = New1
    ;   New1 \== [],
        append(Vars, New1, Vars1),
        literal(Bias, Vars1, L2, New2),
        uses_one(L2, New1),
        term_variables(Vars1, Bound),
        \+ implied([L2], [L1], Bound),
        Lits = [L1, L2],
        append(New1, New2, New)
    ).

uses_one(Lit, New) :-
    term_variables(Lit, Vs),
    member(V, Vs),
    member(W-_, New),
    V == W,
    !.

%   Every literal of Lits is a path literal once its new variables are bound: the path
%   query already implies the candidate (it would succeed on every example here).
implied(Lits, PathLits, PV) :-
    \+ \+ ( maplist(matching(PathLits), Lits, Matches),
            subsumes_term(Lits-PV, Matches-PV) ).

matching(PathLits, Lit, Match) :-
    member(Match, PathLits),
    \+ Lit \= Match.

%   The key of a candidate up to the order of its literals and the names of its new
%   variables (the path's variables keep their identity).
canonical(PV, _-(_-cand(Lits, _)), Key) :-
    findall(K, ( permutation(Lits, P),
                 copy_term(PV-P, K),
                 numbervars(K, 0, _) ), Ks),
    min_member(Key, Ks).

% ---- literals as goals ---------------------------------------------------------------------

%!  literal_goal(+Literal, +Facts, +Action, +Necessity, +Last, -Goal) is det.
%
%   Goal proves Literal on an example: action(A) unifies A with the example's Action,
%   necessity(N) N with its Necessity, any other literal is a member of its Facts (the
%   relational state). With Last = true the goal is deterministic (memberchk/2): nothing
%   after it can ask for another solution.

literal_goal(action(T), _, Action, _, _, T = Action) :- !.
literal_goal(necessity(T), _, _, N, _, T = N) :- !.
literal_goal(Lit, Facts, _, _, Last, Goal) :-
    (   Last == index
    ->  Goal = relrl_tg_bias:fact_member(Lit, Facts)
    ;   Last == true
    ->  Goal = memberchk(Lit, Facts)
    ;   Goal = member(Lit, Facts)
    ).

%!  conj_goal(+Literals, +Facts, +Action, +Necessity, +Bound, -Goal) is det.
%
%   Goal proves the conjunction Literals (a list); Bound is `last` when the conjunction is
%   proved once (its last literal becomes deterministic), `all` when every solution counts,
%   `index` when every solution counts and Facts is an index of the facts (facts_index/2).

conj_goal([], _, _, _, _, true).
conj_goal([L], Facts, A, N, Bound, G) :-
    !,
    (   Bound == last
    ->  Last = true
    ;   Bound == index
    ->  Last = index
    ;   Last = false
    ),
    literal_goal(L, Facts, A, N, Last, G).
conj_goal([L|Ls], Facts, A, N, Bound, (G, Gs)) :-
    (   Bound == index
    ->  Last = index
    ;   Last = false
    ),
    literal_goal(L, Facts, A, N, Last, G),
    conj_goal(Ls, Facts, A, N, Bound, Gs).

%!  query_goal(+Literals, +Facts, +Action, +Necessity, +Bound, -Goal) is det.
%
%   As conj_goal/6, for a query whose solutions matter only through the action: Literals
%   are split into their components (literal_components/2), and a component that holds no
%   action/1 literal is proved once (once/1), as is every component when Bound is `last`
%   (the query is proved once). Its variables are then existential: "some ball is still in
%   room a" is true or not whatever the action, and a query that binds the action's
%   arguments from the facts does not prove the action's part again for every such ball,
%   nor does a failing query try every ball before it fails. Goal has the truth value of
%   conj_goal/6's and, with Bound `index`, the same solutions for Action in the same order
%   of first occurrence (the components are independent: their solutions are a product).

query_goal(Lits, Facts, A, N, Bound, Goal) :-
    literal_components(Lits, Comps),
    maplist(component_goal(Facts, A, N, Bound), Comps, Goals),
    list_conj(Goals, Goal).

component_goal(Facts, A, N, Bound, Comp, Goal) :-
    conj_goal(Comp, Facts, A, N, Bound, G),
    (   ( Bound == last ; \+ memberchk(action(_), Comp) ),
        \+ ( Bound == last, Comp = [_] )          % (then G is memberchk/2 already)
    ->  Goal = once(G)
    ;   Goal = G
    ).

%!  literal_components(+Literals:list, -Components:list) is det.
%
%   Components are the lists of Literals (each in its order in Literals) that share
%   variables, directly or through others, in the order of their first literals; a literal
%   without variables is a component of its own.

literal_components([], []).
literal_components([L|Ls], [[L|Comp]|Comps]) :-
    term_variables(L, Vs),
    component_of(Vs, Ls, Comp, Rest),
    literal_components(Rest, Comps).

%   Comp: the literals of Ls linked to the variables Vs (through each other), Rest the
%   others, both in order.
component_of(Vs, Ls, Comp, Rest) :-
    partition(shares(Vs), Ls, In, Out),
    (   In == []
    ->  Comp = [], Rest = Ls
    ;   term_variables(Vs-In, Vs1),
        component_of(Vs1, Out, Comp1, Rest),
        merge_in_order(Ls, In, Comp1, Comp)
    ).

shares(Vs, L) :-
    term_variables(L, LVs),
    member(X, LVs), member(Y, Vs), X == Y,
    !.

%   The literals of A and B (both sub-lists of Ls), in Ls' order.
merge_in_order(Ls, A, B, Merged) :-
    include(in_either(A, B), Ls, Merged).

in_either(A, B, L) :-
    (   member(X, A), X == L
    ->  true
    ;   member(X, B), X == L
    ).

%!  facts_index(+Facts:list, -Index) is det.
%
%   Index finds the facts of Facts (a list of ground facts) that may match a literal without
%   a pass over them (fact_member/2). It is made at once; its parts are made on first use
%   and kept in it: for a relation and an argument position, a map from each value there
%   to the facts that hold it, in Facts' order (one pass and a sort, n log n for n facts).
%   A query that proves a literal of a leaf's path once per solution of the literals before
%   it (a path query with the action open, tg_classes.pl) then costs a look-up per literal,
%   not a pass over the state: it grows with its solutions, not with their product with the
%   state.

facts_index(Facts, facts(Facts, maps([]))).

%!  fact_member(?Literal, +Index) is nondet.
%
%   As member(Literal, Facts) for the facts Index was made from (facts_index/2): the same
%   solutions in the same order. A literal with a ground argument is looked up by the first
%   such (the facts whose argument there is that value, in order); one with none is a
%   member of all the facts.

fact_member(Lit, facts(Facts, Maps)) :-
    (   compound(Lit),
        ground_arg(Lit, I, V)
    ->  compound_name_arity(Lit, Name, Arity),
        position_map(Maps, Facts, Name, Arity, I, Map),
        get_assoc(V, Map, Run),
        member(Lit, Run)
    ;   member(Lit, Facts)
    ).

%   I is the first position of a ground argument V of Lit.
ground_arg(Lit, I, V) :-
    arg(I, Lit, V),
    ground(V),
    !.

%   The map of relation Name/Arity at position I: value - the facts with it there (in
%   order: keysort/2 is stable), made on first use and kept (nb_setarg/3).
position_map(Maps, Facts, Name, Arity, I, Map) :-
    arg(1, Maps, Made),
    (   memberchk(m(Name, Arity, I, Map0), Made)
    ->  Map = Map0
    ;   compound_name_arity(T, Name, Arity),
        findall(V-T, ( member(T, Facts), arg(I, T, V) ), Pairs),
        keysort(Pairs, Sorted),
        group_pairs_by_key(Sorted, Grouped),
        ord_list_to_assoc(Grouped, Map),
        nb_setarg(1, Maps, [m(Name, Arity, I, Map)|Made])
    ).

%!  literal_holds(+Literal, +Facts, +Action, +Necessity) is nondet.
%
%   Literal is true of the example (Facts, Action, Necessity); interpreted, for
%   explanations and tests (the learner's hot path runs compiled goals).

literal_holds(action(T), _, A, _) :- !, T = A.
literal_holds(necessity(T), _, _, N) :- !, T = N.
literal_holds(Lit, Facts, _, _) :- member(Lit, Facts).

% ---- readable text -------------------------------------------------------------------------

%!  name_variables(+Vars:list, -Names:list) is det.
%
%   Names are Name=Var pairs for the typed variables Vars (Var-Type, in order of
%   introduction): the type's initial in capitals, numbered from the second on (P, P1, T).

name_variables(Vars, Names) :-
    foldl(name_variable, Vars, Names, []-[], _).

name_variable(V-Type, Name=V, Seen0-Used0, Seen-Used) :-
    (   atom(Type), sub_atom(Type, 0, 1, _, C0)
    ->  upcase_atom(C0, C)
    ;   C = 'V'
    ),
    aggregate_all(count, member(C, Seen0), K),
    (   K =:= 0
    ->  Name = C
    ;   atom_concat(C, K, Name)
    ),
    Seen = [C|Seen0],
    Used = [Name|Used0].

%!  conj_text(+Literals:list, +Names:list, -Text:string) is det.
%
%   Text writes the conjunction with the variable names Names (Name=Var); variables not
%   named are written _.

conj_text(Lits, Names, Text) :-
    list_conj(Lits, Goal),
    format(string(Text), "~W",
           [Goal, [quoted(true), variable_names(Names), spacing(next_argument),
                   portray(true)]]).

list_conj([], true).
list_conj([L], L) :- !.
list_conj([L|Ls], (L, C)) :- list_conj(Ls, C).

%!  root_refinements(+KB, -Texts:list) is det.
%
%   The candidate tests of an empty tree (one leaf), written as text: what `relrl check`
%   lists for the domain's bias.

root_refinements(KB, Texts) :-
    tg_bias(KB, Bias),
    refinements(Bias, [], [], Cands),
    findall(Text, ( member(cand(Lits, New), Cands),
                    name_variables(New, Names),
                    conj_text(Lits, Names, Text) ), Texts).

% ---- validating the bias -------------------------------------------------------------------

%!  bias_problem(+KB, -Problem) is nondet.
%
%   Problem is problem(File, Line, Message) for a bad relation/1, rmode/1 or rconst/2
%   declaration of KB.

bias_problem(KB, problem(File, Line, Msg)) :-
    declaration(KB, relation(T), Ref),
    relation_problem(T, Msg),
    clause_where(Ref, File, Line).
bias_problem(KB, problem(File, Line, Msg)) :-
    declaration(KB, rconst(T, C), Ref),
    (   \+ atom(T)
    ->  format(string(Msg), "rconst(~q, ~q): the type must be an atom", [T, C])
    ;   \+ ground(C)
    ->  format(string(Msg), "rconst(~q, ~q): the constant must be ground", [T, C])
    ),
    clause_where(Ref, File, Line).
bias_problem(KB, problem(File, Line, Msg)) :-
    declaration(KB, rmode(M), Ref),
    mode_problem(KB, M, Msg),
    clause_where(Ref, File, Line).
bias_problem(KB, problem(File, Line, Msg)) :-
    findall(M-Ref, declaration(KB, rmode(M), Ref), Pairs),
    append(_, [M-_|Later], Pairs),
    member(M2-Ref2, Later),
    M2 =@= M,
    clause_where(Ref2, File, Line),
    mode_text(M, MT),
    format(string(Msg), "rmode ~w is declared twice", [MT]).

relation_problem(T, Msg) :-
    (   \+ callable(T)
    ->  format(string(Msg), "relation(~q): the template must be a callable term, \c
                             e.g. relation(gaze(_Who, _Place))", [T])
    ;   functor(T, Name, Arity),
        memberchk(Name/Arity, [action/1, necessity/1])
    ->  format(string(Msg), "relation(~q): ~q is reserved for the example's \c
                             ~w", [T, Name/Arity, Name])
    ).

mode_problem(KB, M, Msg) :-
    mode_text(M, MT),
    (   \+ callable(M)
    ->  format(string(Msg), "rmode(~w): the mode must be a literal, e.g. \c
                             rmode(gaze(#agent, -place))", [MT])
    ;   bad_mode_arg(M, Bad)
    ->  format(string(Msg), "rmode ~w: bad argument ~q (use +Type, -Type, #Type, a \c
                             constant or a term of these)", [MT, Bad])
    ;   M = action(A)
    ->  pattern(A, P),
        \+ ( ( kb_response(KB, R) ; declared(KB, action(R)) ), \+ R \= P ),
        format(string(Msg), "rmode ~w matches no declared response", [MT])
    ;   M = necessity(A)
    ->  \+ ( A = #(necessity) ; A = -(necessity) ; atomic(A) ),
        format(string(Msg), "rmode ~w: use necessity(#necessity) or necessity(-necessity)",
               [MT])
    ;   functor(M, Name, Arity),
        \+ ( declared(KB, relation(T)), callable(T), functor(T, Name, Arity) )
    ->  length(Us, Arity), U =.. [Name|Us], maplist(=('_'), Us),
        format(string(Msg), "rmode ~w: ~q is not a declared relation (add relation(~w).)",
               [MT, Name/Arity, U])
    ;   mode_type(M, #, T),
        T \== necessity,
        \+ declared(KB, rconst(T, _))
    ->  format(string(Msg), "rmode ~w: no constants of type ~q (add rconst(~q, Value).)",
               [MT, T, T])
    ;   mode_type(M, +, T),
        \+ ( declared(KB, rmode(M2)), mode_type(M2, -, T) )
    ->  format(string(Msg), "rmode ~w: +~q can never be bound (no rmode introduces a \c
                             variable of type ~q with -~q)", [MT, T, T, T])
    ).

%!  bias_warning(+KB, -Warning) is nondet.
%
%   Warning is problem(File, Line, Message) for a #T type whose constants grow with the
%   world: more than 10 of them, or one for each of at least three responses (rconst(place,
%   P) for every look(P)). Every #T literal is one candidate test per constant in every
%   leaf, so such a bias makes the learner's work grow with the world, and a test on one
%   ground place says nothing about the others. File and Line are those of the first rmode
%   that uses #T. A domain with such a bias is valid; relrl check prints the warning.

bias_warning(KB, problem(File, Line, Msg)) :-
    findall(T, ( declared(KB, rmode(M)), mode_type(M, #, T), T \== necessity ), Ts0),
    sort(Ts0, Ts),
    member(T, Ts),
    findall(C, declared(KB, rconst(T, C)), Cs0),
    sort(Cs0, Cs),
    length(Cs, K),
    findall(C, ( member(C, Cs), once(( kb_response(KB, R), term_constant(R, C) )) ), Used),
    length(Used, U),
    (   U >= 3
    ->  Used = [E1, E2|_],
        format(string(Msg), "rconst type ~q has a constant for each of ~d responses' \c
               arguments (~q, ~q, ...): its #~q tests grow with the world (one candidate \c
               per constant in every leaf); use +~q/-~q variables and keep as constants \c
               only the few the task distinguishes, as a type of their own",
               [T, U, E1, E2, T, T, T])
    ;   K > 10
    ->  format(string(Msg), "rconst type ~q has ~d constants: every #~q literal is one \c
               candidate test per constant in every leaf; if they grow with the world, use \c
               +~q/-~q variables", [T, K, T, T, T])
    ),
    once(( declaration(KB, rmode(M), Ref), mode_type(M, #, T) )),
    clause_where(Ref, File, Line).

%!  bias_constants(+Bias, -Constants:list) is det.
%
%   Constants are the constants Bias (tg_bias/2) names: those of rconst/2 and of the
%   necessities, and every atomic argument written in an rmode template. A test sees no
%   other constant of the world than these and those of the example's state.

bias_constants(bias(Modes, Consts), All) :-
    findall(C, ( member(_-Cs, Consts), member(C, Cs), atomic(C) ), C1),
    findall(C, ( member(M, Modes), template_constant(M, C) ), C2),
    append(C1, C2, All).

template_constant(M, C) :-
    compound(M),
    \+ mode_spec(M),
    M =.. [_|Args],
    member(A, Args),
    (   atomic(A)
    ->  C = A
    ;   template_constant(A, C)
    ).

%!  term_constant(+Term, ?Constant) is nondet.
%
%   Constant is an atomic argument of Term, at any depth (not its principal functor):
%   left_3 of look(left_3), of gaze(face, left_3).

term_constant(T, C) :-
    compound(T),
    T =.. [_|Args],
    member(X, Args),
    (   atomic(X)
    ->  C = X
    ;   term_constant(X, C)
    ).

%   A mode written with relrl's operators (#agent, not #(agent)).
mode_text(M, Text) :-
    format(string(Text), "~W", [M, [quoted(true), module(relrl)]]).

bad_mode_arg(M, Bad) :-
    compound(M),
    M =.. [_|Args],
    member(A, Args),
    (   var(A)
    ->  Bad = A
    ;   A = +(T), \+ atom(T) -> Bad = A
    ;   A = -(T), \+ atom(T) -> Bad = A
    ;   A = #(T), \+ atom(T) -> Bad = A
    ;   compound(A), \+ mode_spec(A)
    ->  bad_mode_arg(A, Bad)
    ).

mode_spec(+(_)).
mode_spec(-(_)).
mode_spec(#(_)).

%   A mode term with every +T, -T and #T replaced by a fresh variable.
pattern(M, P) :-
    (   mode_spec(M)
    ->  true
    ;   compound(M)
    ->  M =.. [F|Ms],
        maplist(pattern, Ms, Ps),
        P =.. [F|Ps]
    ;   P = M
    ).

%   Type T appears in mode term M with the mode symbol Sym (+, - or #).
mode_type(M, Sym, T) :-
    compound(M),
    (   M =.. [Sym, T], atom(T)
    ->  true
    ;   \+ mode_spec(M),
        M =.. [_|Args],
        member(A, Args),
        mode_type(A, Sym, T)
    ).

declaration(KB, Head, Ref) :-
    functor(Head, Name, Arity),
    current_predicate(KB:Name/Arity),
    \+ predicate_property(KB:Head, imported_from(_)),
    clause(KB:Head, true, Ref).

%   Where a declaration came from (relrl_check's one definition; check.pl loads this
%   module, so the call is qualified rather than imported).
clause_where(Ref, File, Line) :-
    relrl_check:clause_location(Ref, File, Line).
