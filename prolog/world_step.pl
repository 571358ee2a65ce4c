:- module(relrl_world_step,
          [ world_predicate/2,    % ?Name/Arity, ?Required
            world_defines/2,      % +KB, ?Name/Arity
            world_start/5,        % +KB, +Task, +Size, -State, -Goal
            world_legal/3,        % +KB, +State, -Actions
            world_action/3,       % +KB, +State, ?Action
            world_actions/3,      % +KB, +State, -Actions
            world_action_list/2,  % +Actions, -List
            world_next/6,         % +KB, +Goal, +State0, +Action, -State, -Outcome
            world_view/4,         % +KB, +Goal, +State, -View
            world_max_reward/1,   % -Max
            world_bound/4,        % +KB, +Goal, +State, -Steps
            % for the world's other modules (world_episodes.pl, world_search.pl):
            world_task_goal/4,    % +KB, +Task, +State, -Goal
            world_state_set/4,    % +KB, +Where, +Facts, -State
            world_holds_goal/3,   % +KB, +Goal, +State
            world_contract/4      % +KB, +Goal, +Format, +Args
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(ordsets)).
:- use_module(rules).
:- use_module(guard, [progress_mark/0]).

/** <module> A world's vocabulary and one step

The predicates a world file defines (world_predicate/2; the table in world.pl) and one step
of a world: a start state and an episode's goal, the legal actions, an action's next state
and reward, the learner's view of a state and the step bound. Every goal of the world runs
through relrl_rules (rule_holds/2, rule_solution/2), and a world predicate that breaks the
vocabulary's contract raises an error naming its file and line (world_contract/4).
world.pl re-exports the public predicates.
*/

%!  world_predicate(?PI, ?Required) is nondet.
%
%   PI is a predicate of the world vocabulary; Required is `required` or `optional`.

world_predicate(initial_state/2, required).
world_predicate(task/1, required).
world_predicate(action/1, required).
world_predicate(precondition/2, required).
world_predicate(effect/4, required).
world_predicate(goal/2, required).
world_predicate(task_goal/3, optional).
world_predicate(goal_fact/2, optional).
world_predicate(derived/2, optional).
world_predicate(reward/5, optional).
world_predicate(step_bound/3, optional).
world_predicate(optimal_steps/3, optional).
world_predicate(sizes/2, optional).
world_predicate(discount/1, optional).
world_predicate(learner_param/3, optional).
world_predicate(task_rmode/2, optional).
world_predicate(task_own_bias/1, optional).
world_predicate(signature/1, optional).
world_predicate(subtype/2, optional).
world_predicate(type/2, optional).

%!  world_defines(+KB, +PI) is semidet.
%
%   The world loaded into KB defines PI (Name/Arity) itself (not an imported predicate).

world_defines(KB, PI) :-
    defines(KB, PI).

defines(KB, Name/Arity) :-
    current_predicate(KB:Name/Arity),
    functor(Head, Name, Arity),
    \+ predicate_property(KB:Head, imported_from(_)).

% ---- one step ------------------------------------------------------------------------------

%!  world_start(+KB, +Task, +Size:integer, -State, -Goal) is det.
%
%   A start state of a world of Size objects and the goal of an episode of Task in it,
%   drawn with library(random): a state that already satisfies the goal is drawn again (at
%   most 100 times). Raises an error naming initial_state/2 when it fails or gives no state.

world_start(KB, Task, Size, State, Goal) :-
    must_be(positive_integer, Size),
    start(KB, Task, Size, 100, State, Goal).

start(KB, Task, Size, Tries, State, Goal) :-
    Init = initial_state(Size, S0),
    (   rule_holds(KB, Init)
    ->  true
    ;   contract(KB, initial_state(Size, _), "initial_state/2 failed for size ~q", [Size])
    ),
    state_set(KB, initial_state(Size, _), S0, S1),
    task_goal(KB, Task, S1, G),
    (   Tries > 1,
        holds_goal(KB, G, S1)
    ->  T1 is Tries - 1,
        start(KB, Task, Size, T1, State, Goal)
    ;   State = S1,
        Goal = G
    ).

task_goal(KB, Task, State, Goal) :-
    (   defines(KB, task_goal/3)
    ->  copy_term(Task, T),
        (   rule_holds(KB, task_goal(T, State, Goal0))
        ->  true
        ;   contract(KB, task_goal(Task, State, _), "task_goal/3 failed for task ~q", [Task])
        )
    ;   Goal0 = Task
    ),
    (   ground(Goal0)
    ->  Goal = Goal0
    ;   contract(KB, task_goal(Task, State, _), "task_goal/3 left the goal ~q unbound (the \c
                 goal of an episode must be ground)", [Goal0])
    ).

%   A state: a list of ground facts, made an ordered set.
state_set(KB, Where, S0, S) :-
    (   is_list(S0), ground(S0)
    ->  sort(S0, S)
    ;   contract(KB, Where, "~q is not a list of ground facts (a state)", [S0])
    ).

holds_goal(KB, Goal, State) :-
    rule_holds(KB, goal(Goal, State)).

%!  world_legal(+KB, +State, -Actions:list) is det.
%
%   The actions legal in State (world_action/3), in the order they are found, without
%   duplicates.

world_legal(KB, State, Actions) :-
    world_actions(KB, State, Goal),
    world_action_list(Goal, Actions).

%!  world_action(+KB, +State, ?Action) is nondet.
%
%   Action is legal in State: an action/1 template bound by precondition/2. Action may come
%   partly bound (move(b1, _)): the world completes it, and must then give exactly the
%   legal actions that match (world_check.pl tries it). A solution must be ground.

world_action(KB, State, A) :-
    rule_solution(KB, action(A)),
    rule_solution(KB, precondition(A, State)),
    (   ground(A)
    ->  true
    ;   copy_term(A, Shown),
        numbervars(Shown, 0, _, [singletons(true)]),
        contract(KB, precondition(A, State), "precondition/2 left the action ~W unbound (it \c
                 must bind every argument of the template)",
                 [Shown, [quoted(true), numbervars(true)]])
    ).

%!  world_actions(+KB, +State, -Actions) is det.
%
%   Actions is actions(A, Goal): Goal binds A to each action legal in State
%   (world_action/3), the form in which the episode runner gives a learner the legal
%   actions of a state (learner_choose/7, learner_update/3). No list of them is made: a
%   learner asks what it reads (tg: whether some legal action reaches a leaf of its tree,
%   tg_classes.pl); one that reads every action (qtable) lists them (world_legal/3).

world_actions(KB, State, actions(A, relrl_world:world_action(KB, State, A))).

%!  world_action_list(+Actions, -List:list) is det.
%
%   List holds the actions of an actions(A, Goal) term (world_actions/3) in the order Goal
%   finds them, without duplicates: what a learner that reads every legal action lists.

world_action_list(actions(A, Goal), List) :-
    findall(A, Goal, List0),
    list_to_set(List0, List).

%!  world_next(+KB, +Goal, +State0, +Action, -State, -Outcome) is det.
%
%   State is State0 after Action (effect/4: deletes, then adds); Outcome is
%   outcome(Reward, Reached), Reached true when State satisfies Goal.

world_next(KB, Goal, S0, A, S, outcome(R, Reached)) :-
    Effect = effect(A, S0, Del, Add),
    (   rule_holds(KB, Effect)
    ->  true
    ;   contract(KB, effect(A, S0, _, _), "effect/4 failed for the legal action ~q", [A])
    ),
    state_set(KB, effect(A, S0, _, _), Del, DelSet),
    state_set(KB, effect(A, S0, _, _), Add, AddSet),
    ord_subtract(S0, DelSet, S1),
    ord_union(S1, AddSet, S),
    (   holds_goal(KB, Goal, S)
    ->  Reached = true
    ;   Reached = false
    ),
    (   defines(KB, reward/5)
    ->  (   rule_holds(KB, reward(Goal, S0, A, S, R0))
        ->  (   reward_ok(R0)
            ->  R = R0
            ;   world_max_reward(Max),
                (   integer(R0),
                    number_codes(R0, Digits),
                    length(Digits, D),
                    D > 20
                ->  format(string(Shown), "an integer of ~D digits", [D])
                ;   format(string(Shown), "~q", [R0])
                ),
                contract(KB, reward(Goal, S0, A, S, _), "reward/5 gave ~w for the action ~q: \c
                         a reward must be a finite number of magnitude at most ~g",
                         [Shown, A, Max])
            )
        ;   contract(KB, reward(Goal, S0, A, S, _), "reward/5 must give a number for every \c
                     step (it failed for the action ~q)", [A])
        )
    ;   Reached == true
    ->  R = 1
    ;   R = 0
    ),
    progress_mark.      % the gateway's time limit of a batch of episodes counts from
                        % here (relrl_guard:progress_watch/2), so a rule that loops is
                        % stopped after the limit however long the batch runs

%!  world_view(+KB, +Goal, +State, -View:list) is det.
%
%   What a learner reads: State's facts, the goal's facts (goal_fact/2) and the derived
%   ones (derived/2, given the state's and the goal's facts), an ordered set.

world_view(KB, Goal, State, View) :-
    (   defines(KB, goal_fact/2)
    ->  findall(F, rule_solution(KB, goal_fact(Goal, F)), GFs)
    ;   GFs = []
    ),
    (   GFs == []
    ->  SG = State
    ;   sort(GFs, GFSet),
        ord_union(State, GFSet, SG)
    ),
    (   defines(KB, derived/2)
    ->  findall(F, rule_solution(KB, derived(F, SG)), DFs)
    ;   DFs = []
    ),
    append([SG, DFs], V0),
    (   ground(V0)
    ->  sort(V0, View)
    ;   contract(KB, derived(_, State), "goal_fact/2 or derived/2 gave a fact that is not \c
                 ground", [])
    ).

%!  world_max_reward(-Max:float) is det.
%
%   A reward (reward/5) is a finite number of magnitude at most Max: learned values then
%   stay finite and within what a saved policy may hold (policy.pl).

world_max_reward(1.0e6).

reward_ok(R) :-
    (   integer(R)
    ->  world_max_reward(Max),
        abs(R) =< Max
    ;   float(R),
        float_class(R, Class),
        memberchk(Class, [zero, subnormal, normal]),
        world_max_reward(Max),
        abs(R) =< Max
    ).

%!  world_bound(+KB, +Goal, +State, -Steps:positive_integer) is det.
%
%   Steps is the step bound of an episode of Goal from State: the world's step_bound/3,
%   else 100. Raises an error naming step_bound/3 when it fails or gives anything but a
%   positive integer.

world_bound(KB, Goal, State, Bound) :-
    bound(KB, Goal, State, Bound).

bound(KB, Goal, State, Bound) :-
    (   defines(KB, step_bound/3)
    ->  (   rule_holds(KB, step_bound(Goal, State, B))
        ->  (   integer(B), B > 0
            ->  Bound = B
            ;   contract(KB, step_bound(Goal, State, _), "step_bound/3 gave ~q for ~q: it \c
                         must give a positive integer", [B, Goal])
            )
        ;   contract(KB, step_bound(Goal, State, _), "step_bound/3 failed for ~q (it must \c
                     give a positive integer)", [Goal])
        )
    ;   Bound = 100
    ).

%   A world predicate broke the vocabulary's contract: an error naming its file and line.
contract(KB, Goal, Format, Args) :-
    format(string(Message), Format, Args),
    rule_where(KB, Goal, Where),
    throw(relrl_rule_error(Goal, Where, error(domain_error(world_vocabulary, Message), _))).

%!  world_task_goal(+KB, +Task, +State, -Goal) is det.
%!  world_state_set(+KB, +Where, +Facts, -State) is det.
%!  world_holds_goal(+KB, +Goal, +State) is semidet.
%!  world_contract(+KB, +Goal, +Format, +Args) is det.
%
%   For the world's other modules: the goal of an episode of Task from State (task_goal/3,
%   ground), Facts as a state (an ordered set; an error naming Where when they are not a
%   list of ground facts), Goal holds in State (goal/2), and the error of a world predicate
%   Goal that broke the vocabulary's contract (Format and Args say how).

world_task_goal(KB, Task, State, Goal) :-
    task_goal(KB, Task, State, Goal).

world_state_set(KB, Where, Facts, State) :-
    state_set(KB, Where, Facts, State).

world_holds_goal(KB, Goal, State) :-
    holds_goal(KB, Goal, State).

world_contract(KB, Goal, Format, Args) :-
    contract(KB, Goal, Format, Args).
