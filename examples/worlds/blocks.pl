/*  Blocks world: the relational reinforcement-learning benchmark (Dzeroski, De Raedt &
    Driessens, "Relational Reinforcement Learning", Machine Learning 43, 2001; Driessens,
    Ramon & Blockeel, RRL-TG, ECML 2001), stated in relrl's world vocabulary (docs/worlds.md).

    Load it with relrl (relrl check --world examples/worlds/blocks.pl) or in plain swipl:
        swipl prolog/relrl.pl examples/worlds/blocks.pl
        ?- initial_state(4, S), task_goal(on(_, _), S, G), optimal_steps(G, S, N).

    Blocks b1 ... bN stand on the floor or on one another. A state holds on(X, Y) for each
    block (Y a block or floor) and clear(X) for each block with nothing on it. One action,
    move(X, Y): a clear block X onto a clear block Y, or onto the floor when X is not on it.
    Tasks: stack (all blocks in one tower), unstack (all on the floor), on(A, B) (block A on
    block B, two blocks drawn for each episode and shown to the learner as goal_on(A, B)),
    clear(A) (nothing on block A, drawn for each episode, shown as goal_clear(A)).
    Start states are uniform over all the states of N blocks.
    Reward 1 when the goal is reached, within a step bound of three moves per block.
*/

% ---- states ------------------------------------------------------------------------------

% A random state of Size blocks, uniform over all the states of Size blocks (the method of
% Slaney & Thiebaux, "Blocks World revisited", AIJ 125, 2001): a state is a set of towers.
% Of the N! orders of the blocks cut into K towers at K-1 of the N-1 gaps, each state of K
% towers is made by exactly K! (the K! orders of its towers), so there are
% N! * C(N-1, K-1) / K! states of K towers (the Lah numbers). Draw K with those weights,
% then an order and K-1 cuts uniformly: every state of N blocks is equally likely.
initial_state(Size, State) :-
    blocks(Size, Blocks),
    tower_count(Size, K),
    random_permutation(Blocks, Order),
    Gaps is Size - 1,
    Cuts is K - 1,
    randseq(Cuts, Gaps, Cut0),
    msort(Cut0, CutAt),
    towers(Order, 1, CutAt, Towers),
    foldl(tower_facts, Towers, [], State).

blocks(Size, Blocks) :-
    numlist(1, Size, Is),
    maplist(block_name, Is, Blocks).

block_name(I, B) :-
    atom_concat(b, I, B).

% K, the number of towers, drawn with weight the number of states of N blocks in K towers.
tower_count(N, K) :-
    numlist(1, N, Ks),
    maplist(states_in_towers(N), Ks, Counts),
    sum_list(Counts, Total),
    random_between(1, Total, R),
    pick_count(Ks, Counts, R, K).

states_in_towers(N, K, Count) :-
    factorial(N - 1, F1),
    factorial(K - 1, FK1),
    factorial(N - K, FNK),
    factorial(N, FN),
    factorial(K, FK),
    Count is F1 // (FK1 * FNK) * FN // FK.

factorial(E, F) :-
    N is E,
    factorial(N, 1, F).

factorial(0, F, F) :- !.
factorial(N, F0, F) :-
    F1 is F0 * N,
    N1 is N - 1,
    factorial(N1, F1, F).

pick_count([K|Ks], [C|Cs], R, Pick) :-
    (   R =< C
    ->  Pick = K
    ;   R1 is R - C,
        pick_count(Ks, Cs, R1, Pick)
    ).

% Towers (each bottom first): Order cut after the positions in CutAt (ascending).
towers(Order, _, [], [Order]) :- !.
towers(Order, I, [C|Cs], [Tower|Towers]) :-
    Len is C - I + 1,
    length(Tower, Len),
    append(Tower, Rest, Order),
    I1 is C + 1,
    towers(Rest, I1, Cs, Towers).

tower_facts([Bottom|Above], Facts0, Facts) :-
    foldl(stack_on, Above, Bottom-[on(Bottom, floor)|Facts0], Top-Facts1),
    Facts = [clear(Top)|Facts1].

stack_on(B, Under-Facts, B-[on(B, Under)|Facts]).

% ---- tasks and goals ---------------------------------------------------------------------

task(stack).
task(unstack).
task(on(_, _)).
task(clear(_)).

% on(A, B): two distinct blocks of the state, drawn at random, unless the task names them.
task_goal(on(A, B), State, on(A, B)) :-
    !,
    (   var(A), var(B)
    ->  findall(X, member(on(X, _), State), Blocks),
        random_select(A, Blocks, Others),
        random_member(B, Others)
    ;   true
    ).
% clear(A): a block of the state drawn at random, unless the task names it.
task_goal(clear(A), State, clear(A)) :-
    !,
    (   var(A)
    ->  findall(X, member(on(X, _), State), Blocks),
        random_member(A, Blocks)
    ;   true
    ).
task_goal(Task, _, Task).

goal(stack, State) :-
    aggregate_all(count, member(on(_, floor), State), 1).
goal(unstack, State) :-
    \+ ( member(on(_, Y), State), Y \== floor ).
goal(on(A, B), State) :-
    memberchk(on(A, B), State).
goal(clear(A), State) :-
    memberchk(clear(A), State).

goal_fact(on(A, B), goal_on(A, B)).
goal_fact(clear(A), goal_clear(A)).

step_bound(_, State, Bound) :-
    aggregate_all(count, member(on(_, _), State), N),
    Bound is 3 * N.

% ---- actions -----------------------------------------------------------------------------

action(move(_X, _Y)).

precondition(move(X, Y), State) :-
    clear_block(X, State),
    (   clear_block(Y, State),
        Y \== X
    ;   \+ memberchk(on(X, floor), State),
        Y = floor
    ).

% A block given (a learner's query proposes move(b3, _), one for each block it binds) is
% checked with one memberchk/2 that stops where it finds the fact; an open one is each clear
% block in turn. The same answers in the same order (the state is a set).
clear_block(X, State) :-
    (   nonvar(X)
    ->  memberchk(clear(X), State)
    ;   member(clear(X), State)
    ).

effect(move(X, Y), State, [on(X, Z)|Del], [on(X, Y)|Add]) :-
    memberchk(on(X, Z), State),
    (   Y == floor
    ->  Del = []
    ;   Del = [clear(Y)]
    ),
    (   Z == floor
    ->  Add = []
    ;   Add = [clear(Z)]
    ).

% ---- what the learner sees ---------------------------------------------------------------

% Besides on/2, clear/1 and goal_on/2, three relations computed from the state and the
% goal, each with at most two facts per block (the view grows linearly with the world;
% above/2 over every pair would grow with the square of a tower's height): covers(X, Y), X
% above Y in Y's tower, for the blocks Y the goal names; goal_tower(X), X a block the goal
% names or above one (in a goal block's tower: a block put there buries one); highest(T),
% T the top of a tallest tower.
derived(covers(X, Y), Facts) :-
    findall(Y0, goal_block(Facts, Y0), Ys),
    Ys \== [],
    above_map(Facts, Above),
    member(Y, Ys),
    above(Above, Y, X).
derived(goal_tower(X), Facts) :-
    findall(Y0, goal_block(Facts, Y0), Ys0),
    sort(Ys0, Ys),
    Ys \== [],
    above_map(Facts, Above),
    findall(X0, ( member(Y, Ys), ( X0 = Y ; above(Above, Y, X0) ) ), Xs0),
    sort(Xs0, Xs),                  % (A above B: A's tower is part of B's; each block once)
    member(X, Xs).
derived(highest(T), State) :-
    above_map(State, Above),
    findall(H-Top, ( member(on(B, floor), State), tower_top(Above, B, 1, H, Top) ), Pairs),
    max_member(Max-_, Pairs),
    member(Max-T, Pairs).

% The view is computed at every step: the towers are read through one map from each block
% to the block on it (n log n for n blocks), not by searching the state's list at every
% level of a tower (which grows with the square of the blocks).
above_map(Facts, Above) :-
    findall(Y-X, ( member(on(X, Y), Facts), Y \== floor ), Pairs),
    list_to_assoc(Pairs, Above).

above(Above, Y, X) :-
    get_assoc(Y, Above, Z),
    (   X = Z
    ;   above(Above, Z, X)
    ).

tower_top(Above, B, H0, H, Top) :-
    (   get_assoc(B, Above, C)
    ->  H1 is H0 + 1,
        tower_top(Above, C, H1, H, Top)
    ;   H = H0,
        Top = B
    ).

goal_block(Facts, Y) :-
    member(goal_on(A, B), Facts),
    member(Y, [A, B]).
goal_block(Facts, A) :-
    member(goal_clear(A), Facts).

below(State, T, X) :-
    memberchk(on(T, Y), State),
    Y \== floor,
    (   X = Y
    ;   below(State, Y, X)
    ).

height(State, B, H) :-
    (   memberchk(on(B, Y), State), Y \== floor
    ->  height(State, Y, H0),
        H is H0 + 1
    ;   H = 1
    ).

relation(on(_, _)).
relation(clear(_)).
relation(goal_on(_, _)).
relation(goal_clear(_)).
relation(covers(_, _)).
relation(highest(_)).
relation(goal_tower(_)).

% The types of the relations and of the action: relrl generates the language bias from
% them (docs/worlds.md, A bias from declarations). Blocks are objects, never named by a
% test (a test speaks of *a* block, never of b3); the floor is the one constant.
signature(move(block, place)).
signature(on(block, place)).
signature(clear(block)).
signature(goal_on(block, block)).
signature(goal_clear(block)).
signature(covers(block, block)).
signature(highest(block)).
signature(goal_tower(block)).
subtype(block, place).
type(floor, place).

% ---- the optimal number of moves (verified against a breadth-first search by relrl check) --

% stack: every block outside a tallest tower moves once; unstack: every block not on the
% floor moves once; on(A, B): every block above A or B moves once and A once more, and A
% twice when it stands above B (it must leave B's tower before B is clear).
optimal_steps(stack, State, N) :-
    aggregate_all(count, member(on(_, _), State), Blocks),
    aggregate_all(max(H), ( member(clear(T), State), height(State, T, H) ), Max),
    N is Blocks - Max.
optimal_steps(unstack, State, N) :-
    aggregate_all(count, ( member(on(_, Y), State), Y \== floor ), N).
optimal_steps(on(A, B), State, N) :-
    (   memberchk(on(A, B), State)
    ->  N = 0
    ;   count_above(State, A, NA),
        count_above(State, B, NB),
        (   below(State, A, B)              % A above B
        ->  N is NB + 1
        ;   below(State, B, A)              % B above A
        ->  N is NA + 1
        ;   N is NA + NB + 1
        )
    ).

optimal_steps(clear(A), State, N) :-
    count_above(State, A, N).

count_above(State, X, N) :-
    aggregate_all(count, ( member(on(Y, _), State), below(State, Y, X) ), N).

sizes(train, [3, 4, 5]).
sizes(test, [10, 20, 50]).
