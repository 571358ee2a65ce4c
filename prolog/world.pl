:- module(relrl_world,
          [ world_episodes/3,     % +KB, +Spec, -Episodes
            world_episodes_from/3, % +KB, +Spec, -Episodes
            world_start/5,        % +KB, +Task, +Size, -State, -Goal
            world_legal/3,        % +KB, +State, -Actions
            world_action/3,       % +KB, +State, ?Action
            world_actions/3,      % +KB, +State, -Actions
            world_action_list/2,  % +Actions, -List
            world_next/6,         % +KB, +Goal, +State0, +Action, -State, -Outcome
            world_view/4,         % +KB, +Goal, +State, -View
            world_optimal/5,      % +KB, +Goal, +State, +Limit, -Steps
            world_bfs/5,          % +KB, +Goal, +State, +Limit, -Steps
            world_bound/4,        % +KB, +Goal, +State, -Steps
            world_max_reward/1,   % -Max
            world_info/2,         % +KB, -Info
            world_predicate/2,    % ?Name/Arity, ?Required
            world_defines/2,      % +KB, ?Name/Arity
            world_task/3,         % +KB, +Spec, -Task
            world_verify/5,       % +KB, +Task, +Size, +Count, -Pairs
            world_reachable/5,    % +KB, +Task, +Size, +Limit, -Verdict
            world_for_task/2      % +KB, +Task
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(random)).
:- use_module(library(ordsets)).
:- use_module(library(assoc)).
:- use_module(declarations).
:- use_module(rules).
:- use_module(engine).
:- use_module(kbstate).
:- use_module(guard, [progress_mark/0]).
:- use_module(learner_contract, [learner_hook/1]).
:- use_module(world_bias).

/** <module> Worlds written in Prolog

A *world* is a task stated the way the relational reinforcement-learning literature states
it (Džeroski, De Raedt & Driessens 2001): objects and relations, actions with preconditions
and effects, a goal and a reward. A world file is plain Prolog, loaded into a knowledge base
like a domain (or at the swipl prompt after prolog/relrl.pl). A *state* is a list of ground
facts, kept sorted (an ordered set). The vocabulary (docs/worlds.md):

  | initial_state(+Size, -State)          | a random start state of a world of Size objects (library(random)) |
  | task(Task)                            | a task the world offers: stack, on(_, _) ...        |
  | action(Template)                      | an action template: move(_, _)                      |
  | precondition(?Action, +State)         | binds a template to each action legal in State      |
  | effect(+Action, +State, -Del, -Add)   | the facts the action deletes and adds               |
  | goal(+Goal, +State)                   | State satisfies Goal                                |
  | task_goal(+Task, +State, -Goal)       | optional: the goal of an episode of Task starting in State (on(A, B): two given blocks); default Goal = Task |
  | goal_fact(+Goal, -Fact)               | optional: what the learner is told of the goal (goal_on(a, b)) |
  | derived(-Fact, +Facts)                | optional: relations computed from the state and the goal's facts (covers(X, A)) |
  | reward(+Goal, +S0, +A, +S, -R)        | optional: default 1 when S satisfies Goal, else 0   |
  | step_bound(+Goal, +State, -Steps)     | optional: default 100                               |
  | optimal_steps(+Goal, +State, -Steps)  | optional: the optimal number of steps, when known (relrl check verifies it against a search) |
  | sizes(train|test, Sizes)              | optional: the sizes learning and transfer use by default |
  | task_rmode(Task, Mode)                | optional: a mode of the language bias for episodes of Task only (world_for_task/2) |
  | task_own_bias(Task)                   | optional: Task's bias is its task_rmode/2 modes alone, without rmode/1 |
  | discount(Gamma)                       | optional: the task's discount, the learners' gamma (default theirs) |
  | relation/1, rmode/1, rconst/2         | the learner's view and language bias, as in a domain (docs/tg.md) |
  | signature/1, subtype/2, type/2        | optional: argument types of relations and actions; with no rmode/1 the bias is generated from them (world_bias.pl) |

The learner's view of a state is the state's facts, the goal's facts and the derived ones
(world_view/4), sorted: what a relational learner (tg) reads, and the ground state a table
learner keys on.

**Episodes in one crossing.** world_episodes/3 runs a batch of episodes inside Prolog: draw
a size and a start state, then choose, act, reward and learn until the goal holds, the step
bound is reached or no action is legal. The learner is the knowledge base's configured one
(engine_configure/4), reached through the engine's learner hooks (learner_choose/7,
learner_update/3), and it draws from the knowledge base's own random stream, as in a
control step. The learner gets a state's legal actions as a goal, not a list
(world_actions/3): it asks what it reads, and the runner only whether some action is
legal. A transition into the goal is terminal: its Q-target is the reward alone
(learner_update/3 with `terminal` for the next state). With updates(episode) (RRL's) the
examples of an episode are given to the learner when it ends, last first, so a reward
reaches the start of the episode within one episode; with updates(online) each step's
example is given at once.

**Errors.** Every goal of the world runs through relrl_rules (rule_holds/2,
rule_solution/2): an exception names the rule's file and line. A world predicate that
breaks the vocabulary's contract (a precondition that leaves an action unbound, an effect
that is not two lists of ground facts, a reward that is not a number) raises
relrl_rule_error(Goal, File:Line, error(domain_error(...), _)) naming it the same way.
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

% ---- episodes ------------------------------------------------------------------------------

%!  world_episodes(+KB, +Spec, -Episodes:list) is det.
%
%   Run a batch of episodes with KB's configured learner, inside Prolog. Spec is
%   episodes(Task, Sizes, Count, Mode, Options): Task a task of the world, Sizes the sizes
%   to draw each episode's size from (uniformly), Count the number of episodes, Mode
%   `learn` (explore and learn), `explore` (explore, no learning) or `greedy` (neither).
%   Options: updates(episode|online) (default episode), optimal(Limit) (compute each
%   episode's optimal number of steps: optimal_steps/3, else a breadth-first search of at
%   most Limit states; default 0: none), trace(true) (keep each step's state and action;
%   trace(actions): its action alone, the state [], and no end state: small answers),
%   random(Seed) (draw from a stream of the batch's own, seeded with Seed, and leave KB's
%   stream as it was: how often and how much a learner is evaluated then never changes
%   what it learns, as Gymnasium's seeded reset; each episode's size and start state then
%   depend on Seed and the episode's place in the batch alone; default `own`: KB's stream).
%
%   Episodes are ep(Size, Goal, Steps, Return, Reached, Optimal, Trace): Steps actions
%   taken, Return the sum of rewards, Reached true/false, Optimal an integer or `none`,
%   Trace [] or a list of step(State, Action, Reward) ending with end(State).
%
%   @error domain_error(world_learner, Learner) if KB's learner is not a learner of worlds
%   (learner_serves(Learner, worlds, _), learners.pl).

world_episodes(KB, episodes(Task, Sizes, Count, Mode, Options), Episodes) :-
    must_be(list(positive_integer), Sizes),
    must_be(nonneg, Count),
    Sizes = [_|_],
    batch(KB, Mode, Options, Run, Seed),
    length(Draws, Count),
    maplist(=(draw), Draws),
    seeded(Seed, Draws, Episodes, episode(Run, Task, Sizes)).

%!  world_episodes_from(+KB, +Spec, -Episodes:list) is det.
%
%   Run one episode from each given start state with KB's configured learner, as
%   world_episodes/3 does from drawn ones. Spec is from(Task, Starts, Mode, Options): Starts
%   a list of start(State, Instance), State a list of ground facts and Instance `none` or an
%   instance of Task that is the episode's task (on(b1, b2)); each episode's goal is its
%   task's (task_goal/3, drawn when the task leaves it open). Mode and Options as in
%   world_episodes/3 (the option random(Seed) included). An episode's Size is `none`.

world_episodes_from(KB, from(Task, Starts, Mode, Options), Episodes) :-
    must_be(list, Starts),
    batch(KB, Mode, Options, Run, Seed),
    seeded(Seed, Starts, Episodes, start_episode(Run, Task)).

%   The run of a batch (Mode and Options checked, KB's learner a learner of worlds) and its
%   random(Seed) option (`own`: KB's stream, claimed).
batch(KB, Mode, Options, Run, Seed) :-
    must_be(oneof([learn, explore, greedy]), Mode),
    must_be(list, Options),
    engine_learner(KB, Learner),
    (   relrl_engine:learner_serves(Learner, worlds, _)   % learners.pl: reads the
    ->  true                                              % relational view too
    ;   domain_error(world_learner, Learner)
    ),
    option_(updates(Updates), Options, episode),
    must_be(oneof([episode, online]), Updates),
    option_(optimal(Limit), Options, 0),
    option_(trace(Trace), Options, false),
    option_(random(Seed), Options, own),
    Run = run(KB, Learner, Mode, Updates, Limit, Trace),
    engine_claim_random(KB).

%   seeded(+Seed, +Inputs, -Episodes, :Goal): call(Goal, Input, Episode) for each input.
%   With Seed `own`, from KB's stream; else each episode from a stream of its own, seeded by
%   a draw of a stream seeded with Seed, and KB's stream is left as it was: an episode's
%   size, start state and drawn goal depend on Seed and its place in the batch alone, not
%   on how the learner acted in the episodes before it.
seeded(own, Ins, Outs, Goal) :-
    !,
    maplist(Goal, Ins, Outs).
seeded(Seed, Ins, Outs, Goal) :-
    must_be(nonneg, Seed),
    random_property(state(Own)),
    setup_call_cleanup(set_random(seed(Seed)),
                       ( same_length(Ins, Seeds),
                         maplist(random_between(0, 0xFFFFFFFFFFFF), Seeds),
                         maplist(seeded_episode(Goal), Seeds, Ins, Outs) ),
                       set_random(state(Own))).

seeded_episode(Goal, Seed, In, Out) :-
    set_random(seed(Seed)),
    call(Goal, In, Out).

start_episode(Run, Task, start(State0, Instance), Episode) :-
    Run = run(KB, _, _, _, _, _),
    state_set(KB, initial_state(_, _), State0, State),
    (   Instance == none
    ->  T = Task
    ;   T = Instance
    ),
    task_goal(KB, T, State, Goal),
    (   holds_goal(KB, Goal, State)
    ->  end_trace(Run, State, Trace),
        Episode = ep(none, Goal, 0, 0, true, 0, Trace)
    ;   run_episode(Run, none, State, Goal, Episode)
    ).

option_(Opt, Options, Default) :-
    (   memberchk(Opt, Options)
    ->  true
    ;   arg(1, Opt, Default)
    ).

episode(Run, Task, Sizes, draw, Episode) :-
    Run = run(KB, _, _, _, _, _),
    random_member(Size, Sizes),
    world_start(KB, Task, Size, S0, Goal),
    run_episode(Run, Size, S0, Goal, Episode).

run_episode(Run, Size, S0, Goal, ep(Size, Goal, Steps, Return, Reached, Optimal, Trace)) :-
    Run = run(KB, _, _, _, Limit, _),
    bound(KB, Goal, S0, Bound),
    (   Limit > 0
    ->  world_optimal(KB, Goal, S0, Limit, Optimal)
    ;   Optimal = none
    ),
    world_view(KB, Goal, S0, V0),
    world_actions(KB, S0, A0),
    steps(Run, Goal, S0, V0, A0, 0, Bound, 0, Steps, Return, Reached, [], Examples, Trace),
    (   Run = run(_, Learner, learn, episode, _, _)
    ->  forall(member(T, Examples), ( learner_update(Learner, KB, T), progress_mark ))
    ;   true
    ).

%   steps(Run, Goal, State, View, Legal, T, Bound, ...): from step T, until the goal holds,
%   T reaches Bound or nothing is legal. Legal is the state's world_actions/3 term (no list
%   of the legal actions is made). Examples (updates(episode)) are the episode's
%   transitions, last first.
steps(Run, Goal, S, V, Legal, T, Bound, Ret0, Steps, Return, Reached, Ex0, Ex, Trace) :-
    (   ( T >= Bound ; \+ any_action(Legal) )
    ->  Steps = T, Return = Ret0, Reached = false, Ex = Ex0,
        end_trace(Run, S, Trace)
    ;   Run = run(KB, Learner, Mode, Updates, _, KeepTrace),
        learner_hook(learner_choose(Learner, KB, V, none, Legal, Mode, A)),
        world_next(KB, Goal, S, A, S1, outcome(R, Done)),
        Ret1 is Ret0 + R,
        T1 is T + 1,
        (   Done == true
        ->  Next = terminal, Legal1 = []
        ;   world_view(KB, Goal, S1, V1),
            world_actions(KB, S1, Legal1),
            (   \+ any_action(Legal1)
            ->  Next = terminal                     % a dead end: nothing more to gain
            ;   Next = V1
            )
        ),
        Tr = transition(V, A, none, Legal, R, Done, Next, none, Legal1),
        (   Mode == learn, Updates == online
        ->  learner_update(Learner, KB, Tr), Ex1 = Ex0
        ;   Mode == learn
        ->  Ex1 = [Tr|Ex0]
        ;   Ex1 = Ex0
        ),
        (   KeepTrace == true
        ->  Trace = [step(S, A, R)|Trace1]
        ;   KeepTrace == actions
        ->  Trace = [step([], A, R)|Trace1]
        ;   Trace = Trace1
        ),
        (   Done == true
        ->  Steps = T1, Return = Ret1, Reached = true, Ex = Ex1,
            end_trace(Run, S1, Trace1)
        ;   steps(Run, Goal, S1, V1, Legal1, T1, Bound, Ret1, Steps, Return, Reached, Ex1,
                  Ex, Trace1)
        )
    ).

any_action(actions(_, Goal)) :-
    \+ \+ call(Goal).

end_trace(run(_, _, _, _, _, KeepTrace), S, Trace) :-
    (   KeepTrace == true
    ->  Trace = [end(S)]
    ;   Trace = []
    ).

%   A hook that fails is an error naming it, as in a control step (engine.pl).
learner_update(Learner, KB, Transition) :-
    learner_hook(learner_update(Learner, KB, Transition)).

% ---- optimal steps -------------------------------------------------------------------------

%!  world_optimal(+KB, +Goal, +State, +Limit, -Steps) is det.
%
%   Steps is the least number of actions that take State to one satisfying Goal: the
%   world's optimal_steps/3 when it defines it, else world_bfs/5 with at most Limit states;
%   `unreachable` when the search proves no state satisfying Goal reachable, `none` when
%   neither gives it (no search, or one stopped by its limit).

world_optimal(KB, Goal, State, Limit, Steps) :-
    (   defines(KB, optimal_steps/3)
    ->  (   rule_holds(KB, optimal_steps(Goal, State, N)), integer(N), N >= 0
        ->  Steps = N
        ;   contract(KB, optimal_steps(Goal, State, _), "optimal_steps/3 must give a \c
                     non-negative integer for ~q", [Goal])
        )
    ;   world_bfs(KB, Goal, State, Limit, Steps)
    ).

%!  world_bfs(+KB, +Goal, +State, +Limit:integer, -Steps) is det.
%
%   Breadth-first search over the world's own dynamics (world_legal/3, world_next/6): Steps
%   is the least number of actions from State to a state satisfying Goal; `unreachable`
%   when the search visited every state reachable from State (at most Limit) and none
%   satisfies Goal; `none` when it stopped at Limit states without finding one.

world_bfs(KB, Goal, State, Limit, Steps) :-
    must_be(nonneg, Limit),
    search(KB, Goal, State, Limit, Steps).

%   Steps: the least number of actions, `unreachable` when every reachable state was visited
%   without reaching Goal, `none` when Limit states were visited.
search(KB, Goal, State, Limit, Steps) :-
    (   holds_goal(KB, Goal, State)
    ->  Steps = 0
    ;   list_to_assoc([State-0], Seen),
        bfs([State], [], 0, KB, Goal, Seen, 1, Limit, Steps)
    ).

%   Frontier: the states at depth D; Next: those found at depth D + 1 so far.
bfs([], Next, D, KB, Goal, Seen, N, Limit, Steps) :-
    (   Next == []
    ->  Steps = unreachable
    ;   D1 is D + 1,
        bfs(Next, [], D1, KB, Goal, Seen, N, Limit, Steps)
    ).
bfs([S|Frontier], Next0, D, KB, Goal, Seen0, N0, Limit, Steps) :-
    world_legal(KB, S, As),
    expand(As, KB, Goal, S, Seen0, Seen, N0, N, Next0, Next, Found),
    (   Found == true
    ->  Steps is D + 1
    ;   N > Limit
    ->  Steps = none
    ;   bfs(Frontier, Next, D, KB, Goal, Seen, N, Limit, Steps)
    ).

expand([], _, _, _, Seen, Seen, N, N, Next, Next, false).
expand([A|As], KB, Goal, S, Seen0, Seen, N0, N, Next0, Next, Found) :-
    world_next(KB, Goal, S, A, S1, outcome(_, Reached)),
    (   Reached == true
    ->  Found = true, Seen = Seen0, N = N0, Next = Next0
    ;   get_assoc(S1, Seen0, _)
    ->  expand(As, KB, Goal, S, Seen0, Seen, N0, N, Next0, Next, Found)
    ;   put_assoc(S1, Seen0, 0, Seen1),
        N1 is N0 + 1,
        expand(As, KB, Goal, S, Seen1, Seen, N1, N, [S1|Next0], Next, Found)
    ).

% ---- a task's own language bias -----------------------------------------------------------

%!  world_for_task(+KB, +Task) is det.
%
%   The learner configured next in KB (engine_configure/4) learns Task: the modes of
%   task_rmode(T, Mode) for a T that Task is an instance of join the bias (rmode/1) of that
%   run, through tg_bias's extra_rmode/2. Background knowledge that serves one task can
%   mislead another: highest/1, the top of a tallest tower, is what stacking needs, and a
%   tree that splits on it while unstacking values moves by tower heights seen in small
%   worlds. When the world declares task_own_bias(T) for such a T, Task's task_rmode/2 modes
%   are the whole bias (tg_bias's own_rmodes/1): the rmode/1 shared by the other tasks are
%   left out. Call it before engine_configure/4; a later call changes only the next run.

world_for_task(KB, Task) :-
    must_be(atom, KB),
    must_be(callable, Task),
    kb_set(KB, task, Task).

:- multifile relrl_tg_bias:extra_rmode/2, relrl_tg_bias:own_rmodes/1.

relrl_tg_bias:extra_rmode(KB, Mode) :-
    atom(KB),
    kb_get(KB, task, Task),
    Task \== none,
    declared(KB, task_rmode(T, Mode)),
    subsumes_term(T, Task).

%   A world that declares no rmode/1: the bias generated from its signature/1, subtype/2
%   and type/2 declarations (world_bias.pl), shared by all its tasks.
relrl_tg_bias:extra_rmode(KB, Mode) :-
    atom(KB),
    \+ declared(KB, rmode(_)),
    world_bias_modes(KB, Modes),
    member(Mode, Modes).

relrl_tg_bias:own_rmodes(KB) :-
    atom(KB),
    kb_get(KB, task, Task),
    Task \== none,
    declared(KB, task_own_bias(T)),
    subsumes_term(T, Task),
    !.

% ---- what the world offers -----------------------------------------------------------------

%!  world_info(+KB, -Info:list) is det.
%
%   Info is [tasks(Tasks), actions(Templates), relations(Templates), sizes(Train, Test),
%   optimal(Known), discount(Gamma)]: the world's declarations (sizes [] when not declared;
%   Known true when the world states its optimal number of steps; Gamma `none` when the
%   world states no discount).

world_info(KB, [tasks(Tasks), actions(Actions), relations(Relations), sizes(Train, Test),
                optimal(Known), discount(Gamma)]) :-
    (   declared(KB, discount(G)), number(G)
    ->  Gamma = G
    ;   Gamma = none
    ),
    findall(T, declared(KB, task(T)), Tasks),
    findall(A, declared(KB, action(A)), Actions),
    findall(R, declared(KB, relation(R)), Relations),
    (   declared(KB, sizes(train, Train0))
    ->  Train = Train0
    ;   Train = []
    ),
    (   declared(KB, sizes(test, Test0))
    ->  Test = Test0
    ;   Test = []
    ),
    (   defines(KB, optimal_steps/3)
    ->  Known = true
    ;   Known = false
    ).

%!  world_task(+KB, +Spec, -Task) is semidet.
%
%   Task is the world's task Spec names: an atom names the declared task of that name
%   (on names on(_, _)); a compound must be an instance of a declared task (on(b1, b2)).
%   Fails when the world declares no such task.

world_task(KB, Spec, Task) :-
    findall(T, declared(KB, task(T)), Tasks),
    (   atom(Spec),
        member(T, Tasks),
        functor(T, Spec, _)
    ->  Task = T
    ;   compound(Spec),
        member(T, Tasks),
        subsumes_term(T, Spec)
    ->  Task = Spec
    ).

%!  world_reachable(+KB, +Task, +Size, +Limit, -Verdict) is det.
%
%   Verdict says whether the goal of Task (a task instance: on(b1, b2)) can be reached in
%   a world of Size objects, by a breadth-first search of at most Limit states from each of
%   three start states drawn with seed 0 (the generator of no knowledge base):
%   `reachable` from one of them, `unreachable` when each search visited every state it
%   could reach, else `unknown`. A task whose goal names an object the world does not
%   have at that size, or a relation no state can hold (on(b1, b1)), is `unreachable`.

world_reachable(KB, Task, Size, Limit, Verdict) :-
    must_be(positive_integer, Size),
    must_be(nonneg, Limit),
    set_random(seed(0)),
    findall(V, ( between(1, 3, _),
                 world_start(KB, Task, Size, S, Goal),
                 search(KB, Goal, S, Limit, Steps),
                 reach_verdict(Steps, V) ), Vs),
    (   memberchk(reachable, Vs)
    ->  Verdict = reachable
    ;   Vs = [_|_],
        forall(member(V, Vs), V == unreachable)
    ->  Verdict = unreachable
    ;   Verdict = unknown
    ).

reach_verdict(Steps, reachable) :-
    integer(Steps),
    !.
reach_verdict(unreachable, unreachable) :- !.
reach_verdict(_, unknown).

%!  world_verify(+KB, +Task, +Size, +Count, -Pairs:list) is det.
%
%   Pairs are Declared-Searched for Count random start states of Task at Size: the
%   optimal number of steps world_optimal/5 gives (the world's optimal_steps/3) and the one
%   a breadth-first search finds (world_bfs/5, at most 200,000 states; `none` beyond).
%   Draws from the knowledge base's random stream.

world_verify(KB, Task, Size, Count, Pairs) :-
    must_be(nonneg, Count),
    engine_claim_random(KB),
    length(Pairs, Count),
    maplist(verify_one(KB, Task, Size), Pairs).

verify_one(KB, Task, Size, Declared-Searched) :-
    world_start(KB, Task, Size, S, Goal),
    world_optimal(KB, Goal, S, 0, Declared),
    world_bfs(KB, Goal, S, 200000, Searched).
