:- module(relrl_check,
          [ check_domain/2,       % +KB, -Problems
            rule_listing/2,       % +KB, -Rules
            bias_listing/2,       % +KB, -Listing
            body_goal/2,          % +Body, -Goal
            data_goal/2,          % +Declaration, -Goal
            clause_location/3     % +ClauseRef, -File, -Line
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(pairs)).
:- use_module(declarations).
:- use_module(tg_bias).

/** <module> Validating a domain

check_domain/2 lists what is wrong with the domain loaded into a knowledge base:

  - a goal in a rule body (a fact's definition, a constraint rule, a behaviour rule's
    antecedent, a necessity input, an ETG test) that calls an undefined predicate;
  - a response used in a behaviour or constraint rule that is not declared;
  - a stimulus, fact, response or necessity declared twice;
  - a necessity unit parameter that is missing, unknown or not a number;
  - a property, input or behaviour rule about something that is not declared;
  - a bad relational view or language bias (relation/1, rmode/1, rconst/2; see
    tg_bias.pl): a relation that is not defined, an rmode of an undeclared relation or with
    a bad argument, a #Type without constants, a +Type no rmode can bind, an action mode
    that matches no response.

Each problem is problem(File, Line, Message) with Message a string. Syntax errors and
singleton variables are reported by the loader (see the Python gateway).
*/

%!  check_domain(+KB, -Problems:list) is det.
%
%   Problems lists every problem found in the domain of KB, in file order.

check_domain(KB, Problems) :-
    must_be(atom, KB),
    findall(P, problem(KB, P), Problems0),
    sort(Problems0, Problems1),
    map_list_to_pairs(problem_key, Problems1, Keyed),
    keysort(Keyed, Sorted),
    pairs_values(Sorted, Problems).

problem_key(problem(File, Line, _), File-Line).

problem(KB, P) :- undefined_call(KB, P).
problem(KB, P) :- undeclared_response(KB, P).
problem(KB, P) :- duplicate_declaration(KB, P).
problem(KB, P) :- bad_unit(KB, P).
problem(KB, P) :- undeclared_reference(KB, P).
problem(KB, P) :- empty_declaration(KB, P).
problem(KB, P) :- bias_problem(KB, P).

%!  clause_location(+Ref, -File, -Line) is det.
%
%   Where the clause Ref came from ('' and 0 when unknown).

clause_location(Ref, File, Line) :-
    (   clause_property(Ref, file(File0))
    ->  File = File0
    ;   File = ''
    ),
    (   clause_property(Ref, line_count(Line0))
    ->  Line = Line0
    ;   Line = 0
    ).

%   Every clause of a predicate the domain itself defines (not imported ones).

domain_clause(KB, Head, Body, Ref) :-
    current_predicate(KB:Name/Arity),
    functor(Head, Name, Arity),
    \+ predicate_property(KB:Head, imported_from(_)),
    \+ predicate_property(KB:Head, foreign),
    catch(clause(KB:Head, Body, Ref),            % a protected (system-like) predicate
          error(permission_error(access, private_procedure, _), _), fail).

declaration_clause(KB, Head, Ref) :-
    functor(Head, Name, Arity),
    current_predicate(KB:Name/Arity),
    \+ predicate_property(KB:Head, imported_from(_)),
    clause(KB:Head, true, Ref).

%   Undefined predicates called from a clause body or from a goal stored as data.

undefined_call(KB, problem(File, Line, Msg)) :-
    domain_clause(KB, Head, Body, Ref),
    (   body_goal(Body, Goal)
    ;   data_goal(Head, Goal)
    ),
    undefined_goal(KB, Goal, PI),
    clause_location(Ref, File, Line),
    functor(Head, HN, HA),
    format(string(Msg), "~q calls undefined predicate ~q", [HN/HA, PI]).

%!  data_goal(+Declaration, -Goal) is semidet.
%
%   Goal is the goal a declaration holds as data: fact(G), unit_input(_, G, _),
%   satisfier(_, G, _), behaviour(G, _, _, _), etg_test(G).

data_goal(fact(G), G).
data_goal(unit_input(_, G, _), G).
data_goal(satisfier(_, G, _), G).
data_goal(behaviour(G, _, _, _), G).
data_goal(etg_test(G), G).
data_goal(relation(G), G).

%!  body_goal(+Body, -Goal) is nondet.
%
%   Goal is a goal of the clause body Body, through control constructs and meta-calls
%   (not through module-qualified goals).

body_goal(Var, _) :- var(Var), !, fail.
body_goal(true, _) :- !, fail.
body_goal((A, B), G) :- !, ( body_goal(A, G) ; body_goal(B, G) ).
body_goal((A ; B), G) :- !, ( body_goal(A, G) ; body_goal(B, G) ).
body_goal((A -> B), G) :- !, ( body_goal(A, G) ; body_goal(B, G) ).
body_goal((A *-> B), G) :- !, ( body_goal(A, G) ; body_goal(B, G) ).
body_goal(\+ A, G) :- !, body_goal(A, G).
body_goal(call(A), G) :- !, body_goal(A, G).
body_goal(once(A), G) :- !, body_goal(A, G).
body_goal(ignore(A), G) :- !, body_goal(A, G).
body_goal(forall(A, B), G) :- !, ( body_goal(A, G) ; body_goal(B, G) ).
body_goal(findall(_, A, _), G) :- !, body_goal(A, G).
body_goal(aggregate_all(_, A, _), G) :- !, body_goal(A, G).
body_goal(_:_, _) :- !, fail.          % module-qualified goals are the author's business
body_goal(G, G) :- callable(G).

%   For fact(F), F itself (not only its body) must be defined.

undefined_goal(KB, Goal, PI) :-
    callable(Goal),
    Goal \= _:_,
    functor(Goal, Name, Arity),
    PI = Name/Arity,
    \+ defined_in(KB, Goal).

%   Visible: defined in KB, inherited from its import modules (relrl, user, system) or
%   autoloadable (a library predicate such as last/2 or list_to_assoc/2), which SWI-Prolog
%   answers without loading the library.

defined_in(KB, Goal) :-
    predicate_property(KB:Goal, visible).

%   Responses used in behaviour and constraint rules must be declared.

undeclared_response(KB, problem(File, Line, Msg)) :-
    (   declaration_clause(KB, behaviour(_, R, _, _), Ref)
    ;   domain_clause(KB, forbidden(R), _, Ref)
    ),
    nonvar(R),
    \+ kb_response(KB, R),
    clause_location(Ref, File, Line),
    format(string(Msg), "response ~q is used but not declared (add response(~q).)", [R, R]).

%   Declarations that appear twice.

duplicate_declaration(KB, problem(File, Line, Msg)) :-
    member(Kind, [stimulus, fact, response, necessity]),
    Head =.. [Kind, X],
    findall(X-Ref, declaration_clause(KB, Head, Ref), Pairs),
    append(_, [X-_|Later], Pairs),
    member(X2-Ref2, Later),
    X2 =@= X,
    clause_location(Ref2, File, Line),
    format(string(Msg), "~w ~q is declared twice", [Kind, X]).
duplicate_declaration(KB, problem(File, Line, Msg)) :-
    findall(N-P-Ref, declaration_clause(KB, unit(N, P, _), Ref), Triples),
    append(_, [N-P-_|Later], Triples),
    member(N-P-Ref2, Later),
    clause_location(Ref2, File, Line),
    format(string(Msg), "unit parameter ~q of necessity ~q is declared twice", [P, N]).

%   Necessity units: every required parameter, numeric, known names.

bad_unit(KB, problem(File, Line, Msg)) :-
    declaration_clause(KB, unit(N, P, V), Ref),
    clause_location(Ref, File, Line),
    (   \+ unit_parameter_name(P)
    ->  findall(Q, unit_parameter_name(Q), Qs),
        format(string(Msg), "unknown unit parameter ~q of necessity ~q (known: ~w)", [P, N, Qs])
    ;   \+ number(V)
    ->  format(string(Msg), "unit parameter ~q of necessity ~q must be a number, not ~q",
               [P, N, V])
    ).
bad_unit(KB, problem(File, Line, Msg)) :-
    declaration_clause(KB, necessity(N), Ref),
    unit_parameter_name(P),
    P \== initial,
    \+ unit_parameter(KB, N, P, _),
    clause_location(Ref, File, Line),
    format(string(Msg), "necessity ~q has no ~q parameter (add unit(~q, ~q, Value).)",
           [N, P, N, P]).
bad_unit(KB, problem(File, Line, Msg)) :-
    (   declaration_clause(KB, unit_input(N, G, W), Ref)
    ;   declaration_clause(KB, satisfier(N, G, W), Ref)
    ),
    \+ number(W),
    clause_location(Ref, File, Line),
    format(string(Msg), "input ~q of necessity ~q must have a numeric weight, not ~q",
           [G, N, W]).
bad_unit(KB, problem(File, Line, Msg)) :-
    declaration_clause(KB, behaviour(_, R, _, F), Ref),
    \+ ( number(F), F >= 0 ),
    clause_location(Ref, File, Line),
    format(string(Msg), "behaviour rule for ~q must have a non-negative numeric fitness, not ~q",
           [R, F]).

%   Properties, parameters, inputs and rules that name undeclared things.

undeclared_reference(KB, problem(File, Line, Msg)) :-
    declaration_clause(KB, stimulus_property(S, _), Ref),
    \+ kb_stimulus(KB, S),
    clause_location(Ref, File, Line),
    format(string(Msg), "property of undeclared stimulus ~q", [S]).
undeclared_reference(KB, problem(File, Line, Msg)) :-
    (   declaration_clause(KB, unit(N, _, _), Ref)
    ;   declaration_clause(KB, unit_input(N, _, _), Ref)
    ;   declaration_clause(KB, satisfier(N, _, _), Ref)
    ;   declaration_clause(KB, behaviour(_, _, N, _), Ref), N \== none
    ),
    \+ kb_necessity(KB, N),
    clause_location(Ref, File, Line),
    format(string(Msg), "necessity ~q is used but not declared (add necessity(~q).)", [N, N]).

empty_declaration(KB, problem('', 0, Msg)) :-
    member(Kind-What, [stimulus-stimuli, response-responses]),
    Head =.. [Kind, _],
    \+ declared(KB, Head),
    format(string(Msg), "the domain declares no ~w (add ~w(Name).)", [What, Kind]).

%!  rule_listing(+KB, -Rules:list) is det.
%
%   Rules holds the behaviour rules and constraint rules of KB, each written as Prolog
%   source text (a string), in file order.

rule_listing(KB, Rules) :-
    findall(S,
            (   member(Head, [behaviour(_, _, _, _), forbidden(_)]),
                domain_clause(KB, Head, Body, _),
                with_output_to(string(S0), portray_clause((Head :- Body))),
                split_string(S0, "", "\n", [S])
            ),
            Rules).

%!  bias_listing(+KB, -Listing) is det.
%
%   Listing is bias(Relations, Refinements, Warnings): the relation/1 templates of KB
%   written as text, the candidate tests the tg learner's refinement operator gives for an
%   empty tree (strings), or [] for a domain without a language bias, and the warnings
%   about the bias (tg_bias:bias_warning/2: a #Type whose constants grow with the world),
%   problem(File, Line, Message) terms.

bias_listing(KB, bias(Relations, Refinements, Warnings)) :-
    findall(S, ( declared(KB, relation(T)),
                 copy_term(T, T1),
                 term_variables(T1, Vs),
                 maplist(=('$VAR'('_')), Vs),
                 format(string(S), "~W", [T1, [quoted(true), numbervars(true),
                                              spacing(next_argument)]]) ),
            Relations),
    (   declared(KB, rmode(_))
    ->  root_refinements(KB, Refinements)
    ;   Refinements = []
    ),
    findall(W, bias_warning(KB, W), Warnings).
