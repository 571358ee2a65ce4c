:- module(relrl_world_episodes,
          [ world_episodes/3,     % +KB, +Spec, -Episodes
            world_episodes_from/3 % +KB, +Spec, -Episodes
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(random)).
:- use_module(engine).
:- use_module(guard, [progress_mark/0]).
:- use_module(learner_contract, [learner_hook/1]).
:- use_module(world_step).
:- use_module(world_search, [world_optimal/5]).

/** <module> A world's episodes in one crossing

world_episodes/3 runs a batch of episodes inside Prolog: draw a size and a start state,
then choose, act, reward and learn until the goal holds, the step bound is reached or no
action is legal; world_episodes_from/3 does the same from given start states. The learner
is the knowledge base's configured one, reached through the engine's learner hooks
(world.pl says more). world.pl re-exports these predicates.
*/


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
    world_state_set(KB, initial_state(_, _), State0, State),
    (   Instance == none
    ->  T = Task
    ;   T = Instance
    ),
    world_task_goal(KB, T, State, Goal),
    (   world_holds_goal(KB, Goal, State)
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
    world_bound(KB, Goal, S0, Bound),
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
