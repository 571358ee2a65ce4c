/*  Delivery: a robot on a grid fetches a parcel and brings it to the dock. A world of
    another shape than blocks world (navigation, an object carried, actions that name
    directions rather than objects), stated in relrl's world vocabulary (docs/worlds.md).

        relrl check --world examples/worlds/delivery.pl
        relrl learn examples/worlds/delivery.pl --task deliver --episodes 300

    A world of size N is an N x N grid of cells c_X_Y. The state holds side(N), robot(C),
    dock(C) and parcel(C) (the parcel on the floor of cell C) or carried (the robot holds it).
    Actions: go(Dir) to the next cell in Dir (north, south, east, west) inside the grid,
    pick when the robot stands on the parcel, drop when it carries it. Task deliver: the
    parcel on the floor of the dock. Reward -1 a step, 0 for the step that reaches the goal,
    discount 0.95: a Q-value is about minus the steps still to take, and bounded (at most
    20 in size) whatever a policy does; with discount 1 the values of a policy that never
    reaches the goal have no bound, and in some seeds they diverged.
    The learner sees where each direction leads: closer(Dir, Thing) when a step in Dir brings
    the robot nearer to Thing (parcel or dock), and here(Thing) when it stands on it.
*/

% ---- states ------------------------------------------------------------------------------

initial_state(N, State) :-
    random_cell(N, R),
    random_cell(N, P),
    random_cell(N, D),
    (   P == D
    ->  initial_state(N, State)
    ;   State = [dock(D), parcel(P), robot(R), side(N)]
    ).

random_cell(N, C) :-
    random_between(1, N, X),
    random_between(1, N, Y),
    cell(X, Y, C).

cell(X, Y, C) :-
    atomic_list_concat([c, X, Y], '_', C).

xy(C, X, Y) :-
    atomic_list_concat([c, XA, YA], '_', C),
    atom_number(XA, X),
    atom_number(YA, Y).

% The grid's side is a fact of the state.
grid_size(State, N) :-
    memberchk(side(N), State).

% ---- tasks -------------------------------------------------------------------------------

task(deliver).

goal(deliver, State) :-
    memberchk(dock(D), State),
    memberchk(parcel(D), State).

discount(0.95).

reward(Goal, _, _, State, R) :-
    (   goal(Goal, State)
    ->  R = 0
    ;   R = -1
    ).

step_bound(_, State, Bound) :-
    grid_size(State, N),
    Bound is 6 * N.

% ---- actions -----------------------------------------------------------------------------

action(go(_Dir)).
action(pick).
action(drop).

precondition(go(Dir), State) :-
    memberchk(robot(C), State),
    grid_size(State, N),
    step(Dir, C, N, _).
precondition(pick, State) :-
    memberchk(robot(C), State),
    memberchk(parcel(C), State).
precondition(drop, State) :-
    memberchk(carried, State).

effect(go(Dir), State, [robot(C)], [robot(C1)]) :-
    memberchk(robot(C), State),
    grid_size(State, N),
    step(Dir, C, N, C1).
effect(pick, State, [parcel(C)], [carried]) :-
    memberchk(robot(C), State).
effect(drop, State, [carried], [parcel(C)]) :-
    memberchk(robot(C), State).

step(Dir, C, N, C1) :-
    xy(C, X, Y),
    member(Dir-(DX, DY), [north-(0, 1), south-(0, -1), east-(1, 0), west-(-1, 0)]),
    X1 is X + DX, Y1 is Y + DY,
    between(1, N, X1), between(1, N, Y1),
    cell(X1, Y1, C1).

% ---- what the learner sees ---------------------------------------------------------------

derived(closer(Dir, Thing), State) :-
    memberchk(robot(C), State),
    thing_cell(State, Thing, T),
    grid_size(State, N),
    step(Dir, C, N, C1),
    distance(C1, T, D1),
    distance(C, T, D0),
    D1 < D0.
derived(here(Thing), State) :-
    memberchk(robot(C), State),
    thing_cell(State, Thing, C).

thing_cell(State, parcel, C) :-
    (   memberchk(parcel(C), State)
    ->  true
    ;   memberchk(robot(C), State)              % carried: where the robot is
    ).
thing_cell(State, dock, C) :-
    memberchk(dock(C), State).

distance(A, B, D) :-
    xy(A, XA, YA),
    xy(B, XB, YB),
    D is abs(XA - XB) + abs(YA - YB).

relation(robot(_)).
relation(parcel(_)).
relation(dock(_)).
relation(side(_)).
relation(carried).
relation(closer(_, _)).
relation(here(_)).

% The types of the relations the learner tests and of the actions: relrl generates the
% language bias from them (docs/worlds.md, A bias from declarations). Directions are named
% by the action (a test speaks of the direction go/1 takes), the parcel and the dock by
% name; robot/1, parcel/1, dock/1 and side/1, with the grid's cells, are in the view but
% not tested (no signature).
signature(go(dir)).
signature(pick).
signature(drop).
signature(closer(dir, thing)).
signature(here(thing)).
signature(carried).
type(north, dir).
type(south, dir).
type(east, dir).
type(west, dir).
type(parcel, thing).
type(dock, thing).

% ---- the optimal number of steps ---------------------------------------------------------

optimal_steps(deliver, State, N) :-
    (   goal(deliver, State)
    ->  N = 0
    ;   memberchk(robot(R), State),
        memberchk(dock(D), State),
        (   memberchk(carried, State)
        ->  distance(R, D, DD),
            N is DD + 1
        ;   memberchk(parcel(P), State),
            distance(R, P, DP),
            distance(P, D, DD),
            N is DP + 1 + DD + 1
        )
    ).

sizes(train, [3, 4, 5]).
sizes(test, [10, 20, 50]).
