:- module(relrl_world_check,
          [ world_problems/2      % +KB, -Problems
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(random)).
:- use_module(library(pairs)).
:- use_module(declarations).
:- use_module(rules).
:- use_module(engine, [engine_pause/0]).
:- use_module(check, [body_goal/2, clause_location/3]).
:- use_module(tg_bias, [bias_problem/2]).
:- use_module(world).
:- use_module(guard, [message_text/2]).

/** <module> Validating a world file

world_problems/2 lists what is wrong with the world loaded into a knowledge base, as
problem(File, Line, Message) terms, and what may be, as warning(File, Line, Message) terms,
in file order (File '' for the world as a whole; a note that the run stopped comes last):

  - a required predicate of the vocabulary that the world does not define (world.pl);
  - a clause that calls an undefined predicate;
  - a task/1, action/1 or sizes/2 declaration of the wrong shape;
  - a bad relational view or language bias (relation/1, rmode/1, rconst/2; tg_bias.pl);
  - what running the world shows: for every task, a few episodes of random legal actions
    from random start states of the smallest training size (seeded, so the same problems
    every time). A goal of the world that raises an error or breaks the vocabulary's
    contract (an unbound action, an effect that is not two lists of ground facts, a step
    bound that is not a positive integer, a reward that is not a finite number within
    world_max_reward/1 ...) is a problem at that rule's file and line; so is a fact of the
    learner's view that no relation/1 declares, and an action no action/1 template covers;
  - whether each episode's goal can be reached: a breadth-first search from its start
    state that visits every reachable state without meeting the goal is a problem
    ("unreachable", at the task's declaration); one stopped by its limit of states is a
    warning naming the limit;
  - an action/1 template that no precondition/2 bound in any state of those episodes: a
    warning at the template;
  - optimal_steps/3, when the world defines it, checked against a breadth-first search over
    the world's own dynamics (world_bfs/5) on random start states of the training sizes up
    to five objects: a different number is a problem at optimal_steps/3.

A problem is reported once, at its place, not once per episode (a rule that fails the same
way for every task is one line); the run stops at the first error a world goal raises, and
after ten problems and warnings.

A time limit, Ctrl-C or a resource error outside the world's own goals is not a problem of
the world: it propagates.
*/

%!  world_problems(+KB, -Problems:list) is det.
%
%   Problems lists the problems (problem(File, Line, Message)) and warnings
%   (warning(File, Line, Message)) found in the world loaded into KB, in file order.

world_problems(KB, Problems) :-
    must_be(atom, KB),
    findall(P, static_problem(KB, P), Static),
    (   Static == [],
        \+ missing_required(KB, _)
    ->  run_problems(KB, Run, Stopped)
    ;   Run = [], Stopped = []
    ),
    append(Static, Run, All),
    sort(All, Problems0),
    map_list_to_pairs(problem_key, Problems0, Keyed),
    keysort(Keyed, Sorted),
    pairs_values(Sorted, Problems1),
    append(Problems1, Stopped, Problems).

problem_key(Item, File-Line) :-
    arg(1, Item, File),
    arg(2, Item, Line).

% ---- what the file says --------------------------------------------------------------------

static_problem(KB, problem('', 0, Msg)) :-
    missing_required(KB, Name/Arity),
    format(string(Msg), "the world defines no ~q (a world needs initial_state/2, task/1, \c
                         action/1, precondition/2, effect/4 and goal/2; see docs/worlds.md)",
           [Name/Arity]).
static_problem(KB, problem(File, Line, Msg)) :-
    world_clause(KB, Head, Body, Ref),
    body_goal(Body, Goal),
    undefined(KB, Goal, PI),
    clause_location(Ref, File, Line),
    functor(Head, HN, HA),
    format(string(Msg), "~q calls undefined predicate ~q", [HN/HA, PI]).
static_problem(KB, problem(File, Line, Msg)) :-
    member(Head-Check, [task(T)-callable(T), action(T)-callable(T)]),
    world_clause(KB, Head, true, Ref),
    \+ Check,
    clause_location(Ref, File, Line),
    format(string(Msg), "~q: the argument must be a term, e.g. task(stack), \c
                         action(move(_, _))", [Head]).
static_problem(KB, problem(File, Line, Msg)) :-
    world_clause(KB, sizes(K, L), true, Ref),
    \+ ( memberchk(K, [train, test]), is_list(L), L = [_|_], maplist(positive, L) ),
    clause_location(Ref, File, Line),
    format(string(Msg), "sizes(~q, ~q): use sizes(train, [3, 4, 5]) or sizes(test, [...]) \c
                         with positive integers", [K, L]).
static_problem(KB, problem(File, Line, Msg)) :-
    world_clause(KB, learner_param(L, N, V), true, Ref),
    \+ ( atom(L), atom(N), number(V) ),
    clause_location(Ref, File, Line),
    format(string(Msg), "learner_param(~q, ~q, ~q): a learner, a parameter's name and a \c
                         number, e.g. learner_param(tg, temperature, 1.0)", [L, N, V]).
static_problem(KB, problem(File, Line, Msg)) :-
    world_clause(KB, discount(G), true, Ref),
    \+ ( number(G), G > 0, G =< 1 ),
    clause_location(Ref, File, Line),
    format(string(Msg), "discount(~q): the discount must be a number in (0, 1]", [G]).
static_problem(KB, problem(File, Line, Msg)) :-
    world_clause(KB, task_rmode(T, M), true, Ref),
    (   \+ ( declared(KB, task(T0)), \+ T0 \= T )
    ->  format(string(Msg), "task_rmode(~q, ~q): no declared task is ~q", [T, M, T])
    ;   \+ callable(M)
    ->  format(string(Msg), "task_rmode(~q, ~q): the mode must be a literal", [T, M])
    ;   M \= action(_),
        functor(M, Name, Arity),
        \+ ( declared(KB, relation(R)), callable(R), functor(R, Name, Arity) )
    ->  format(string(Msg), "task_rmode(~q, ~q): ~q is not a declared relation (add \c
                             relation/1)", [T, M, Name/Arity])
    ),
    clause_location(Ref, File, Line).
static_problem(KB, problem(File, Line, Msg)) :-
    world_clause(KB, task_own_bias(T), true, Ref),
    (   \+ ( declared(KB, task(T0)), \+ T0 \= T )
    ->  format(string(Msg), "task_own_bias(~q): no declared task is ~q", [T, T])
    ;   \+ ( declared(KB, task_rmode(T1, M)), \+ T1 \= T, M = action(_) )
    ->  format(string(Msg), "task_own_bias(~q): its bias would have no action test (give \c
                             task_rmode(~q, action(...)) modes)", [T, T])
    ),
    clause_location(Ref, File, Line).
static_problem(KB, P) :-
    bias_problem(KB, P).

positive(X) :-
    integer(X),
    X > 0.

missing_required(KB, PI) :-
    world_predicate(PI, required),
    \+ world_defines(KB, PI).

world_clause(KB, Head, Body, Ref) :-
    current_predicate(KB:Name/Arity),
    functor(Head, Name, Arity),
    \+ predicate_property(KB:Head, imported_from(_)),
    \+ predicate_property(KB:Head, foreign),
    catch(clause(KB:Head, Body, Ref),
          error(permission_error(access, private_procedure, _), _), fail).

undefined(KB, Goal, Name/Arity) :-
    callable(Goal),
    Goal \= _:_,
    functor(Goal, Name, Arity),
    \+ predicate_property(KB:Goal, visible).   % defined, inherited or autoloadable

% ---- what running it shows -----------------------------------------------------------------

%!  check_limit(-Name, -Value) is det.
%
%   The run's limits: `items`, the problems and warnings found before it stops; `bfs`, the
%   states a reachability search visits from a start state (as relrl learn's optimum).

check_limit(items, 10).
check_limit(bfs, 20000).

%   Episodes of random legal actions, 3 per task, seeded; then optimal_steps/3 against the
%   search. A problem is reported once, at its place (the first episode that shows it); the
%   run stops at the first error a world goal raises (every later episode would meet it
%   again) or once check_limit(items, _) problems are found. When every episode ran, an
%   action template that no precondition bound in any of their states is a warning.
run_problems(KB, Items, Stopped) :-
    engine_pause,
    set_random(seed(0)),
    sizes(KB, Sizes),
    Sizes = [Smallest|_],
    findall(T, declared(KB, task(T)), Tasks),
    findall(episode(Task, Smallest), ( member(Task, Tasks), between(1, 3, _) ), Episodes),
    (   world_defines(KB, optimal_steps/3)
    ->  findall(optimal(Task, Size), ( member(Task, Tasks), member(Size, Sizes), Size =< 5,
                                       between(1, 10, _) ), Optimal)
    ;   Optimal = []
    ),
    append(Episodes, Optimal, Jobs),
    run_jobs(Jobs, KB, acc([], [], go), acc(Items0, Seen0, Stop)),
    (   Stop == go
    ->  sort(Seen0, Seen),
        findall(W, never_bound(KB, Seen, W), Ws),
        Stopped = []
    ;   Stop == limit
    ->  check_limit(items, Max),
        format(string(Msg), "the check stopped after ~D problems and warnings: fix them \c
                             and check again", [Max]),
        Ws = [], Stopped = [warning('', 0, Msg)]
    ;   Ws = [], Stopped = []
    ),
    reverse(Items0, Items1),
    append(Items1, Ws, Items).

%   acc(Items, Seen, Stop): the items kept so far (newest first, one per kind and place),
%   the legal actions met in the episodes, and go, raised or limit.
run_jobs([], _, Acc, Acc).
run_jobs([Job|Jobs], KB, Acc0, Acc) :-
    Acc0 = acc(Items0, Seen0, Stop0),
    (   Stop0 \== go
    ->  Acc = Acc0
    ;   (   catch(job(Job, KB, Found, Seen1), relrl_rule_error(Goal, Where, E),
                  ( rule_problem(Goal, Where, E, found(P)), Found = [P], Seen1 = [],
                    Raised = true ))
        ->  true
        ;   Found = [], Seen1 = []
        ),
        foldl(keep_item, Found, Items0, Items),
        append(Seen1, Seen0, Seen),
        length(Items, N),
        check_limit(items, Max),
        (   Raised == true
        ->  Stop = raised
        ;   N >= Max
        ->  Stop = limit
        ;   Stop = go
        ),
        run_jobs(Jobs, KB, acc(Items, Seen, Stop), Acc)
    ).

%   A problem or warning is kept when none of its kind is kept at its place yet.
keep_item(Item, Items, Out) :-
    item_place(Item, Place),
    (   member(Kept, Items),
        item_place(Kept, Place)
    ->  Out = Items
    ;   Out = [Item|Items]
    ).

item_place(Item, Kind-File-Line) :-
    functor(Item, Kind, 3),
    arg(1, Item, File),
    arg(2, Item, Line).

job(episode(Task, Size), KB, Found, Seen) :-
    random_episode(KB, Task, Size, Found, Seen).
job(optimal(Task, Size), KB, Found, []) :-
    optimal_mismatch(KB, Task, Size, F),
    found_list(F, Found).

found_list(none, []).
found_list(found(P), [P]).

sizes(KB, Sizes) :-
    (   declared(KB, sizes(train, S0)), is_list(S0), S0 = [_|_]
    ->  msort(S0, Sizes)
    ;   Sizes = [3]
    ).

%   One episode of random legal actions from a drawn start state: the episode's step bound,
%   whether its goal is reachable (a breadth-first search), then a walk. Found lists what
%   it shows; Seen the legal actions of the states it met.
random_episode(KB, Task, Size, Found, Seen) :-
    world_start(KB, Task, Size, S0, Goal),
    world_bound(KB, Goal, S0, _),
    reachable(KB, Task, Goal, S0, Reach),
    (   view_problem(KB, Goal, S0, F)
    ->  Seen = []
    ;   walk(KB, Goal, S0, 30, [], Seen, F)
    ),
    found_list(F, Walked),
    append(Reach, Walked, Found).

%   An unreachable goal is a problem, a search stopped by its limit a warning, both at the
%   task's declaration.
reachable(KB, Task, Goal, S0, Found) :-
    check_limit(bfs, Limit),
    world_bfs(KB, Goal, S0, Limit, Steps),
    (   integer(Steps)
    ->  Found = []
    ;   task_where(KB, Task, File, Line),
        (   Steps == unreachable
        ->  format(string(Msg), "task ~q: the goal ~q is unreachable from the drawn start \c
                                 state ~q (a breadth-first search over the world's actions \c
                                 visited every state reachable from it)", [Task, Goal, S0]),
            Found = [problem(File, Line, Msg)]
        ;   format(string(Msg), "task ~q: a breadth-first search stopped at its limit of ~D \c
                                 states without reaching the goal ~q from the drawn start \c
                                 state ~q (the goal may be unreachable; relrl learn gives \c
                                 such an episode no optimum)", [Task, Limit, Goal, S0]),
            Found = [warning(File, Line, Msg)]
        )
    ).

task_where(KB, Task, File, Line) :-
    (   world_clause(KB, task(T), true, Ref),
        T =@= Task
    ->  clause_location(Ref, File, Line)
    ;   File = '', Line = 0
    ).

%   An action/1 template that no legal action of the checked episodes' states matched.
never_bound(KB, Seen, warning(File, Line, Msg)) :-
    world_clause(KB, action(T), true, Ref),
    callable(T),
    \+ ( member(A, Seen), subsumes_term(T, A) ),
    clause_location(Ref, File, Line),
    copy_term(T, Shown),
    numbervars(Shown, 0, _, [singletons(true)]),
    format(string(Msg), "action(~W): precondition/2 bound this template in no state of the \c
                         checked episodes (a precondition that never holds?)",
           [Shown, [quoted(true), numbervars(true)]]).

%   Seen0/Seen: the legal actions met, accumulated.
walk(KB, Goal, S, N, Seen0, Seen, Found) :-
    world_legal(KB, S, As),
    append(As, Seen0, Seen1),
    (   member(A, As), \+ covered_action(KB, A)
    ->  rule_where(KB, action(_), Where),
        where_file_line(Where, File, Line),
        format(string(Msg), "precondition/2 gave the action ~q, which no action/1 template \c
                             covers", [A]),
        Found = found(problem(File, Line, Msg)), Seen = Seen1
    ;   partial_mismatch(KB, S, As, T, Got, Expected)
    ->  rule_where(KB, precondition(_, _), Where),
        where_file_line(Where, File, Line),
        copy_term(T, Shown),
        numbervars(Shown, 0, _, [singletons(true)]),
        format(string(Msg), "precondition/2 called with ~W gives ~q, but the legal actions \c
                             it matches are ~q (learners ask with some arguments bound: the \c
                             answer must be the same actions)",
               [Shown, [quoted(true), numbervars(true)], Got, Expected]),
        Found = found(problem(File, Line, Msg)), Seen = Seen1
    ;   N =:= 0
    ->  Found = none, Seen = Seen1
    ;   As == []
    ->  Found = none, Seen = Seen1
    ;   random_member(A, As),
        world_next(KB, Goal, S, A, S1, outcome(_, Reached)),
        (   view_problem(KB, Goal, S1, Found)
        ->  Seen = Seen1
        ;   Reached == true
        ->  Found = none, Seen = Seen1
        ;   N1 is N - 1,
            walk(KB, Goal, S1, N1, Seen1, Seen, Found)
        )
    ).

%   A template with one argument bound to a value some legal action has there, for which
%   the world's legal actions (world_action/3 with the template) are not the legal actions
%   it matches: a precondition written for an open template only (tg proves its leaves'
%   tests first, which bind some arguments, and lets the world complete the action).
partial_mismatch(KB, S, As, T, Got, Expected) :-
    findall(Name/Arity-I-V, ( member(A, As), compound(A), functor(A, Name, Arity),
                              arg(I, A, V) ), Keys0),
    sort(Keys0, Keys),
    member(Name/Arity-I-V, Keys),
    functor(T, Name, Arity),
    arg(I, T, V),
    findall(T, world_action(KB, S, T), Got0),
    sort(Got0, Got),
    include(subsumes_term(T), As, Expected0),
    sort(Expected0, Expected),
    Got \== Expected,
    !.

covered_action(KB, A) :-
    declared(KB, action(T)),
    subsumes_term(T, A),
    !.

%   A fact of the learner's view that no relation/1 template covers (when the world
%   declares relations at all).
view_problem(KB, Goal, State, found(problem(File, Line, Msg))) :-
    declared(KB, relation(_)),
    world_view(KB, Goal, State, View),
    member(F, View),
    \+ ( declared(KB, relation(T)), subsumes_term(T, F) ),
    !,
    functor(F, Name, Arity),
    rule_where(KB, relation(_), Where),
    where_file_line(Where, File, Line),
    format(string(Msg), "the learner's view holds ~q, but no relation/1 declares ~q (add \c
                         relation(~q).)", [F, Name/Arity, Name/Arity]).

%   An error of a world goal: a problem at its file and line (a time limit, Ctrl-C or a
%   halt/0,1 the rule called is not a problem to list: it propagates and ends the check).
rule_problem(Goal, Where, E, found(problem(File, Line, Msg))) :-
    (   ( E == time_limit_exceeded ; E == relrl_interrupted ; E == relrl_halt_called )
    ->  throw(relrl_rule_error(Goal, Where, E))
    ;   true
    ),
    where_file_line(Where, File, Line),
    (   E = error(domain_error(world_vocabulary, Text), _)
    ->  Msg = Text
    ;   E = error(resource_error(Resource), _)
    ->  format(string(Msg), "~q ran out of ~w (a recursion without end?)", [Goal, Resource])
    ;   message_text(E, Text0),
        first_line(Text0, Text),
        format(string(Msg), "~q raised: ~s", [Goal, Text])
    ).

%   A message's first line that holds text: a problem is one line.
first_line(Text0, Line) :-
    split_string(Text0, "\n", " \t", Lines),
    (   member(Line, Lines),
        Line \== ""
    ->  true
    ;   Line = ""
    ).

where_file_line(Where, File, Line) :-
    (   Where = File:Line
    ->  true
    ;   File = '', Line = 0
    ).

%   optimal_steps/3 against a breadth-first search on one random start state.
optimal_mismatch(KB, Task, Size, Found) :-
    world_start(KB, Task, Size, S, Goal),
    world_optimal(KB, Goal, S, 0, Declared),
    world_bfs(KB, Goal, S, 50000, Searched),
    (   integer(Searched),
        Declared \== Searched
    ->  rule_where(KB, optimal_steps(_, _, _), Where),
        where_file_line(Where, File, Line),
        format(string(Msg), "optimal_steps/3 gives ~q for ~q from ~q; a breadth-first \c
                             search over the world's actions finds ~q", [Declared, Goal, S,
                                                                         Searched]),
        Found = found(problem(File, Line, Msg))
    ;   Found = none
    ).
