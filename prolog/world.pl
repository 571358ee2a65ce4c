:- module(relrl_world,
          [ world_info/2,         % +KB, -Info
            world_task/3,         % +KB, +Spec, -Task
            world_for_task/2      % +KB, +Task
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(declarations).
:- use_module(rules).
:- use_module(kbstate).
:- use_module(world_bias).
:- reexport(world_step,                % the vocabulary and one step: world_start/5,
            except([ world_task_goal/4,  % world_legal/3, world_action(s)/3, world_next/6,
                     world_state_set/4,  % world_view/4, world_bound/4, ... (world_step.pl);
                     world_holds_goal/3, % these four serve world.pl's sibling modules only
                     world_contract/4
                   ])).
:- reexport(world_episodes).        % world_episodes/3, world_episodes_from/3
:- reexport(world_search).          % world_optimal/5, world_bfs/5, world_reachable/5, world_absent/4,
                                    % world_verify/5

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
  | learner_param(Learner, Name, Value)   | optional: the world's value of a learner's parameter, over the learner's defaults in worlds (temperature) |
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

The vocabulary and one step are world_step.pl's, the episodes world_episodes.pl's, the
searches (optimal steps, reachability) world_search.pl's; this module re-exports them and
holds what a world offers (world_info/2, world_task/3) and a task's own language bias
(world_for_task/2).
*/

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
%   optimal(Known), discount(Gamma), learner_params(Params)]: the world's declarations
%   (sizes [] when not declared; Known true when the world states its optimal number of
%   steps; Gamma `none` when the world states no discount; Params a [Learner, Name, Value]
%   list for each learner_param/3).

world_info(KB, [tasks(Tasks), actions(Actions), relations(Relations), sizes(Train, Test),
                optimal(Known), discount(Gamma), learner_params(Params)]) :-
    findall([L, N, V], declared(KB, learner_param(L, N, V)), Params),
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
    (   world_defines(KB, optimal_steps/3)
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

