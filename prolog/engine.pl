:- module(relrl_engine,
          [ engine_configure/4,       % +KB, +Learner, +Params, +Seed
            engine_step/6,            % +KB, +Percepts, +Emitted, +Mode, +Want, -Out
            engine_end_episode/1,     % +KB
            engine_explain/3,         % +KB, +When, -Explanation
            engine_text/2,            % +KB, -Text
            engine_graph/2,           % +KB, -Graph
            engine_knowledge/2,       % +KB, -Terms
            engine_size/2,            % +KB, -Size
            engine_policy/3,          % +KB, +Header, -Text
            engine_snapshot/2,        % +KB, -Snapshot
            engine_restore/2,         % +KB, +Snapshot
            engine_keep/2,            % +KB, +Slot
            engine_resume/2,          % +KB, +Slot
            engine_reseed/2,          % +KB, +Seed
            engine_forget/1,          % +KB
            engine_pause/0,
            engine_claim_random/1,    % +KB
            engine_param/3,           % +KB, ?Name, ?Value
            engine_params/2,          % +KB, -Params
            engine_config/3,          % +KB, ?Key, ?Value
            engine_policy_info/2,     % +KB, -Info
            engine_learner/2,         % +KB, -Learner
            engine_responses/2,       % +KB, -Responses
            engine_all_allowed/2,     % +KB, +Allowed
            engine_necessities/2,     % +KB, -Necessities
            engine_holds/2,           % +KB, +Goal
            engine_relational_state/2 % +KB, -Facts
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(random)).
:- use_module(library(pairs)).
:- use_module(memory).
:- use_module(declarations).
:- use_module(senses).
:- use_module(state).
:- use_module(motivation).
:- use_module(rules).
:- use_module(kbstate).
:- use_module(learner_contract).
:- use_module(engine_random).
:- set_prolog_flag(optimise, true).   % arithmetic compiled inline (this file only)

/** <module> The control step, inside Prolog

One call of engine_step/6 does all the knowledge work of a control step, so the robot's
loop crosses from Python into Prolog once per step:

    percepts -> working memory -> state code (+ the learner's view of the state)
    -> necessity units and mediator -> reward -> learner update for the previous step
    -> allowed responses -> learner choice

## Learners are hooks

The engine knows no learner by name. A learner is a module that adds clauses, keyed on its
name, to the multifile hooks below (learners.pl loads every learner module); adding one
touches its own file and one line of learners.pl.

  | learner(Name)                                   | registers Name                         |
  | learner_property(Name, external)                | Python chooses (Q-learning over numpy) |
  | learner_property(Name, view(relational))        | reads the relational view only: no state code is computed for it (a step reports code 0) |
  | learner_parameter(Name, Param, Default, Kind)   | a parameter, its default and the values it takes (learners.pl) |
  | learner_serves(Name, Family, Overrides)         | learns tasks of Family (`domains`, `worlds`), with these defaults there (learners.pl) |
  | learner_init(Name, KB, Params)                  | start afresh                           |
  | learner_state(Name, KB, Code, State)            | the learner's view of the state now (default: Code) |
  | learner_choose(Name, KB, State, N, Allowed, Mode, Action) | Mode: learn, explore or greedy |
  | learner_update(Name, KB, Transition)            | transition(S0, A0, N0, Allowed0, R, Reinforced, S1, N1, Allowed1); S1 = terminal: the episode ended in the goal (target R alone; worlds, world.pl) |
  | learner_explain(Name, KB, State, N, Explanation)| why it would choose what it chooses    |
  | learner_size(Name, KB, size(Positions, Details))| memory in the paper's positions        |
  | learner_save(Name, KB, Stream)                  | write the learned knowledge as clauses |
  | learner_policy_term(Name, Term)                 | Term may appear in Name's policy file  |
  | learner_restore(Name, KB, Terms)                | rebuild from policy terms (data)       |
  | learner_policy_info(Name, KB, Info)             | optional: what a policy is tied to in the domain (default: its features and responses) |
  | learner_text(Name, KB, Text)                    | optional: the knowledge as text        |
  | learner_graph(Name, KB, graph(Nodes, Edges))    | optional: a tree as a graph            |
  | learner_knowledge(Name, KB, Terms)              | optional: the knowledge as terms       |
  | learner_end_episode(Name, KB)                   | optional                               |
  | learner_snapshot(Name, KB, Snap) / learner_resume(Name, KB, Snap) | optional: episode state |

## Random numbers

Each knowledge base owns its random stream, so two agents in one process give the same
trajectories as each alone; engine_random.pl keeps it (the generator holds the stream of
the knowledge base that stepped last).

## Between steps

Two things a step keeps from the last one must be let go of before anything else runs:
the random stream the generator holds, and the check that the domain's rules still read
some facts straight off working memory (relrl_state:state_touch/0). engine_pause/0 does
both. relrl's gateway calls it before every call that is not a step (a goal, a user's
query or its next answer, loading a file, keep and resume, ...), so no caller of the
gateway has a rule to follow; a Prolog program that calls engine_step/6 itself calls it
before it draws random numbers of its own or changes rules between steps. A step that
raises an error leaves the stream where the step stopped (as it leaves working memory
and the learner).

## Errors

Domain goals (facts, tests, constraint and behaviour rules, necessity inputs) run through
engine_holds/2: a goal that fails is false; any exception — a time limit, a resource error,
an existence error — propagates, wrapped as relrl_rule_error(Goal, Where, Error) so the
gateway can name the rule.
*/

:- multifile
    learner/1,
    learner_property/2,
    learner_parameter/4,
    learner_serves/3,
    learner_init/3,
    learner_forget/2,
    learner_state/4,
    learner_choose/7,
    learner_update/3,
    learner_explain/5,
    learner_size/3,
    learner_save/3,
    learner_policy_term/2,
    learner_restore/3,
    learner_policy_info/3,
    learner_text/3,
    learner_graph/3,
    learner_knowledge/3,
    learner_end_episode/2,
    learner_snapshot/3,
    learner_resume/3.

%   Each knowledge base's engine is the `engine` part of its record (kbstate.pl), so one
%   knowledge base never sees another's: engine(Run, Prev, Random), where
%     Run = run(Learner, Params, Features, Responses, Units, Reinforcers, Constraints,
%               Necessities, Plan, Caps) — fixed for a run, read without copying; Plan is
%               the state code's plan (relrl_state:state_plan/4), or relational(Plan) for a
%               learner that reads the relational view only (the plan then only tells
%               whether a reinforcer is sensed); Caps the learner's capabilities
%               (learner_property/2), checked when the run was configured
%     Prev    prev(State, Necessity, Allowed) of the last step, or none
%     Random  the KB's random state, while the generator does not hold it (see
%             random_owner/1: while it does, the generator's state is the KB's)
%   Prev is replaced in place (nb_setarg/3) every step; eng(Prev, Random) is how the rest
%   of this module sees the pair (eng/2 gives the stream as it is now).

engine(KB, Engine) :-
    kb_record(KB, Record),
    record_engine(KB, Record, Engine).

%   The engine in KB's Record.
record_engine(KB, Record, Engine) :-
    record_get(Record, engine, Engine0),
    (   Engine0 \== none
    ->  Engine = Engine0
    ;   existence_error(engine_configuration, KB)
    ).

run(KB, Run) :-
    engine(KB, engine(Run, _, _)).

eng(KB, eng(Prev, Random)) :-
    engine(KB, Engine),
    arg(2, Engine, Prev),
    random_now(KB, Engine, Random).

set_eng(KB, eng(Prev, Random)) :-
    engine(KB, Engine),
    nb_setarg(2, Engine, Prev),
    random_replace(KB, Engine, Random).

%!  engine_pause is det.
%
%   Something other than a control step may run now: the stream the random generator
%   holds (the knowledge base's that stepped last) goes back to its knowledge base, so
%   that numbers drawn before the next step of any knowledge base draw from no knowledge
%   base's stream, and the next step checks again which facts it may read straight off
%   working memory (relrl_state:state_touch/0: the rules may change meanwhile).

engine_pause :-
    random_park,
    state_touch.

%!  engine_claim_random(+KB) is det.
%
%   Load KB's random stream into the generator, where it stays until another knowledge
%   base steps or engine_pause/0 puts it away: for a driver that runs the learner's hooks
%   itself, many steps in one call (relrl_world:world_episodes/3).

engine_claim_random(KB) :-
    engine(KB, Engine),
    random_claim(KB, Engine).

%!  engine_learner(+KB, -Learner) is det.
%
%   The learner KB's engine was configured with.

engine_learner(KB, Learner) :-
    run(KB, run(Learner, _, _, _, _, _, _, _, _, _)).

%!  engine_param(+KB, ?Name, ?Value) is nondet.
%!  engine_param(+KB, +Name, -Value) is semidet.
%
%   A parameter of KB's learner (alpha, gamma, epsilon, ...).

engine_param(KB, Name, Value) :-
    run(KB, run(_, Params, _, _, _, _, _, _, _, _)),
    (   atom(Name)
    ->  memberchk(Name=Value, Params)
    ;   member(Name=Value, Params)
    ).

%!  engine_params(+KB, -Params:list) is det.
%
%   The learner's parameters, Name=Value (what learners read in every step).

engine_params(KB, Params) :-
    run(KB, run(_, Params, _, _, _, _, _, _, _, _)).

%!  engine_config(+KB, ?Key, ?Value) is nondet.
%!  engine_config(+KB, +Key, -Value) is semidet.
%
%   What the engine was configured with: learner, params, features (stimulus(S) and fact(F)
%   in code order), responses (in declaration order), units, reinforcers, constraints
%   (true when the domain has constraint rules), necessities.

engine_config(KB, Key, Value) :-
    run(KB, run(Learner, Params, Features, Responses, Units, Reinforcers, Constraints,
                Necessities, _, _)),
    (   Constraints == true
    ->  HasConstraints = true
    ;   HasConstraints = false
    ),
    Config = [learner-Learner, params-Params, features-Features, responses-Responses,
              units-Units, reinforcers-Reinforcers, constraints-HasConstraints,
              necessities-Necessities],
    (   atom(Key)
    ->  memberchk(Key-Value, Config)
    ;   member(Key-Value, Config)
    ).

%!  engine_responses(+KB, -Responses:list) is det.
%
%   The responses in the order engine_step/6 indexes them.

engine_responses(KB, Responses) :-
    run(KB, run(_, _, _, Responses, _, _, _, _, _, _)).

%!  engine_all_allowed(+KB, +Allowed:list) is semidet.
%
%   Allowed, the allowed responses a learner hook was given, is the engine's own list of
%   every response of KB (no constraint rule forbids one this step): a test in constant
%   time (the same term), for a learner that need not look at the responses one by one
%   then. Fails when it is not, or when KB has no engine.

engine_all_allowed(KB, Allowed) :-
    kb_get(KB, engine, engine(run(_, _, _, Responses, _, _, _, _, _, _), _, _)),
    Responses == Allowed.

%!  engine_necessities(+KB, -Necessities:list) is det.
%
%   The necessities in declaration order (the order of a step's unit outputs).

engine_necessities(KB, Necessities) :-
    run(KB, run(_, _, _, _, _, _, _, Necessities, _, _)).

%!  engine_configure(+KB, +Learner, +Params:list, +Seed) is det.
%
%   Prepare KB for a run with Learner (a registered learner) and Params (Name=Value).
%   Working memory, the necessity units and the learner start afresh. Seed, an integer,
%   seeds KB's own random stream; `none` gives it a stream seeded from the clock.
%
%   A learner configured before in KB forgets what it kept (learner_forget/2).
%
%   @error domain_error(learner, Learner) if no learner of that name is registered.
%   @error learner_hooks(Learner, Problems) if Learner lacks a hook it must have or
%   declares (see learner_capabilities/2).

engine_configure(KB, Learner, Params, Seed) :-
    must_be(atom, KB),
    must_be(atom, Learner),
    must_be(list, Params),
    (   learner(Learner)
    ->  true
    ;   findall(L, learner(L), Known),
        domain_error(learner(Known), Learner)
    ),
    learner_capabilities(Learner, Caps),
    forget_learner(KB),
    state_features(KB, Features),
    findall(R, kb_response(KB, R), Responses),
    findall(S, kb_reinforcer(KB, S), Reinforcers),
    findall(N, kb_necessity(KB, N), Necessities),
    rules_mark(RulesMark),                            % what the last run compiled goes
    state_mark(StateMark),                            % once this one is in place
    motivation_units(KB, Units0),
    motivation_compiled(KB, Units0, Units),
    state_plan(KB, Features, Reinforcers, Plan0),
    (   memberchk(view(relational), Caps)
    ->  Plan = relational(Plan0)
    ;   Plan = Plan0
    ),
    (   has_constraints(KB)
    ->  Constraints = true
    ;   Constraints = none                            % no constraint rules: all allowed
    ),
    random_fresh(Seed, Random),
    kb_set(KB, engine, engine(run(Learner, Params, Features, Responses, Units, Reinforcers,
                                  Constraints, Necessities, Plan, Caps),
                              none, Random)),
    wm_clear(KB),
    motivation_reset(KB),
    with_random(KB, learner_hook(learner_init(Learner, KB, Params))),
    rules_forget(KB, RulesMark),
    state_forget(KB, StateMark).

%   The domain has constraint rules: forbidden/1 has clauses, or may get them (dynamic).
%   (relrl declares forbidden/1 in every knowledge base, so it always exists.)
has_constraints(KB) :-
    Head = forbidden(_),
    current_predicate(KB:forbidden/1),
    \+ predicate_property(KB:Head, imported_from(_)),
    (   predicate_property(KB:Head, dynamic)
    ->  true
    ;   predicate_property(KB:Head, number_of_clauses(N)),
        N > 0
    ).

%   Run Goal with KB's random stream in the generator (it stays there: engine_random.pl's
%   random_claim/2).
with_random(KB, Goal) :-
    engine(KB, Engine),
    random_claim(KB, Engine),
    call(Goal).

%!  engine_reseed(+KB, +Seed:integer) is det.
%
%   Seed KB's own random stream.

engine_reseed(KB, Seed) :-
    must_be(integer, Seed),
    engine(KB, Engine),
    random_fresh(Seed, Random),
    random_replace(KB, Engine, Random).

%!  engine_end_episode(+KB) is det.
%
%   End an interaction: no update will link the next step to this one; working memory and
%   the necessity units start afresh.

engine_end_episode(KB) :-
    engine(KB, Engine),
    arg(1, Engine, run(Learner, _, _, _, _, _, _, _, _, Caps)),
    nb_setarg(2, Engine, none),
    wm_clear(KB),
    motivation_reset(KB),
    (   memberchk(end_episode, Caps)
    ->  learner_hook(learner_end_episode(Learner, KB))
    ;   true
    ).

%!  engine_forget(+KB) is det.
%
%   Forget everything relrl keeps for KB: what its learner kept (learner_forget/2), its
%   record (engine, working memory, units, learner, tree, kept snapshots; kbstate.pl),
%   its random stream, its state plans and compiled rules.

engine_forget(KB) :-
    must_be(atom, KB),
    forget_learner(KB),
    random_disown(KB),
    kb_forget(KB),
    state_forget(KB),
    rules_forget(KB).

%   The learner configured in KB (if any) forgets what it keeps outside the record.
forget_learner(KB) :-
    (   kb_record_exists(KB),
        kb_get(KB, engine, engine(run(Learner, _, _, _, _, _, _, _, _, _), _, _))
    ->  learner_hook(learner_forget(Learner, KB)),
        kb_set(KB, learner, none),
        kb_set(KB, tree, none),
        kb_set(KB, inner, none)
    ;   true
    ).

%   Learner has capability Cap (KB's configured run).
capable(KB, Cap) :-
    run(KB, run(_, _, _, _, _, _, _, _, _, Caps)),
    memberchk(Cap, Caps).

%!  engine_step(+KB, +Percepts, +Emitted, +Mode, +Want, -Out) is det.
%
%   One control step. Percepts are this step's perception facts; Emitted is the index
%   (0-based, in declaration order) of the response emitted at the previous step, or -1;
%   Mode is `learn` (update the learner from the previous step and explore), `explore`
%   (act with the learner's exploration without learning) or `greedy` (neither). Want lists
%   what else to report: memory (working memory as Age-Element pairs), memory_size,
%   explain (the learner's explanation for this step's state).
%
%   Out = step(Code, Necessity, Ys, Reward, Reinforced, Allowed, Action, Extras): the state
%   code (0 for a learner with learner_property(L, view(relational)), which never reads
%   it), the active necessity (or none), the necessity units' outputs (a list in
%   declaration order), the reward for the previous response, true/false, the allowed
%   responses as a bit mask (bit i set when response i is allowed; -1 when every response
%   is, as always in a domain without constraint rules), the index of the
%   learner's choice (-1 for a learner outside Prolog, or when nothing is allowed), and
%   Extras, a list of Key-Value pairs for Want.
%
%   The step finds KB's record (kbstate.pl) once and hands it to working memory, the state
%   code and the necessity units; a learner's hooks are given KB, and find the record once
%   per call (kb_record/2).

engine_step(KB, Percepts, EmittedIx, Mode, Want, Out) :-
    kb_record(KB, Record),
    record_engine(KB, Record, Engine),
    Engine = engine(Run, Prev, _),
    random_claim(KB, Engine),
    step(KB, Record, Run, Prev, Percepts, EmittedIx, Mode, Want, Out, Next),
    nb_setarg(2, Engine, Next).

step(KB, Record, run(Learner, Params, _, Responses, Units, _, Constraints, _, Plan, Caps),
     Prev, Percepts, EmittedIx, Mode, Want,
     step(Code, Active, Ys, Reward, Reinforced, AllowedMask, ActionIx, Extras),
     prev(State, Active, Allowed)) :-
    (   EmittedIx >= 0
    ->  nth0(EmittedIx, Responses, Emitted),
        wm_insert(KB, Record, [emitted(Emitted)|Percepts])
    ;   wm_insert(KB, Record, Percepts)
    ),
    view_code(KB, Record, Plan, Code, Reinforced),
    learner_view(Learner, Caps, KB, Code, State),
    motivation_values(KB, Record, Units, _, Ys, Active),
    (   Reinforced == true
    ->  memberchk(reward_positive=Reward, Params)
    ;   memberchk(reward_negative=Reward, Params)
    ),
    allowed(KB, Constraints, Responses, Allowed, AllowedMask),
    (   Mode == learn,
        EmittedIx >= 0,
        Prev = prev(S0, N0, Allowed0)
    ->  (   learner_update(Learner, KB, transition(S0, Emitted, N0, Allowed0, Reward,
                                                   Reinforced, State, Active, Allowed))
        ->  true
        ;   learner_hook_failed(Learner, learner_update/3)
        )
    ;   true
    ),
    (   ( Allowed == [] ; memberchk(external, Caps) )
    ->  ActionIx = -1
    ;   learner_choose(Learner, KB, State, Active, Allowed, Mode, Action)
    ->  (   nth0(ActionIx, Responses, Action)
        ->  true
        ;   domain_error(response, Action)
        )
    ;   learner_hook_failed(Learner, learner_choose/7)
    ),
    extras(Want, KB, Learner, State, Active, Extras).

%   The state code and whether a reinforcer is sensed; for a learner that reads the
%   relational view only, no code (0): the engine does not compute what no one reads.
view_code(KB, Record, Plan, Code, Reinforced) :-
    (   Plan = relational(Plan0)
    ->  Code = 0,
        plan_reinforced(Record, Plan0, Reinforced)
    ;   plan_code(KB, Record, Plan, Code, Reinforced)
    ).

%   The learner's view of the state: its learner_state/4 if it declares `state`, else
%   the code.
learner_view(Learner, Caps, KB, Code, State) :-
    (   memberchk(state, Caps)
    ->  (   learner_state(Learner, KB, Code, State0)
        ->  State = State0
        ;   learner_hook_failed(Learner, learner_state/4)
        )
    ;   State = Code
    ).

extras([], _, _, _, _, []) :- !.
extras(Want, KB, Learner, State, N, Extras) :-
    foldl(extra(KB, Learner, State, N), Want, Extras, []).

extra(KB, _, _, _, memory, [memory-Pairs|T], T) :- !,
    wm_elements(KB, Pairs).
extra(KB, _, _, _, memory_size, [memory_size-Size|T], T) :- !,
    wm_size(KB, Size).
extra(KB, Learner, State, N, explain, [explain-E|T], T) :- !,
    explanation(KB, Learner, State, N, E).
extra(_, _, _, _, What, _, _) :-
    domain_error(step_report, What).

%   Mask is -1 when every response is allowed (no constraint rules): a world with many
%   responses does not pay for a mask of as many bits every step.
allowed(KB, Constraints, Responses, Allowed, Mask) :-
    (   Constraints == none
    ->  Allowed = Responses,
        Mask = -1
    ;   allowed_(Responses, KB, 0, Allowed, 0, Mask)
    ).

allowed_([], _, _, [], Mask, Mask).
allowed_([R|Rs], KB, I, Allowed, Mask0, Mask) :-
    (   forbidden(KB, R)
    ->  Allowed = Allowed1,
        Mask1 = Mask0
    ;   Allowed = [R|Allowed1],
        Mask1 is Mask0 \/ (1 << I)
    ),
    I1 is I + 1,
    allowed_(Rs, KB, I1, Allowed1, Mask1, Mask).

forbidden(KB, R) :-
    engine_holds(KB, forbidden(R)).

%!  engine_holds(+KB, +Goal) is semidet.
%
%   Run the domain goal Goal once in KB. Failure is false; an exception propagates as
%   relrl_rule_error(Goal, Where, Error) (Where is File:Line of the predicate's first
%   clause, or unknown), so a time limit or a resource error in a rule reaches the caller
%   and names the rule.

engine_holds(KB, Goal) :-
    rule_holds(KB, Goal).

%!  engine_relational_state(+KB, -Facts:list) is det.
%
%   Facts are the ground solutions, now, of the domain's relation/1 templates, sorted and
%   without duplicates: the relational view of the state a relational learner reads.

engine_relational_state(KB, Facts) :-
    findall(T, declared(KB, relation(T)), Templates),
    findall(F, ( member(F, Templates), rule_solution(KB, F), ground(F) ), Facts0),
    sort(Facts0, Facts).

%!  engine_explain(+KB, +When, -Explanation) is det.
%
%   Why the learner would choose what it chooses: When is `last` (the last step's state and
%   necessity) or `now` (the state in working memory now; the necessity the units would
%   give now; nothing is learned or moved). Explanation is
%   explanation(Learner, State, Necessity, Detail), Detail from the learner.

engine_explain(KB, When, Explanation) :-
    must_be(oneof([last, now]), When),
    run(KB, run(Learner, _, _, _, Units, _, _, _, Plan, Caps)),
    (   When == last,
        engine(KB, engine(_, prev(State, N, _), _))
    ->  true
    ;   kb_record(KB, Record),
        view_code(KB, Record, Plan, Code, _),
        learner_view(Learner, Caps, KB, Code, State),
        motivation_peek(KB, Units, _, N)
    ),
    explanation(KB, Learner, State, N, Explanation).

explanation(KB, Learner, State, N, explanation(Learner, State, N, Detail)) :-
    learner_hook(learner_explain(Learner, KB, State, N, Detail)).

%!  engine_text(+KB, -Text:string) is det.
%
%   The learner's knowledge drawn as text ("" for a learner that has no drawing).

engine_text(KB, Text) :-
    engine_learner(KB, Learner),
    (   capable(KB, text)
    ->  learner_hook(learner_text(Learner, KB, Text))
    ;   Text = ""
    ).

%!  engine_graph(+KB, -Graph) is det.
%
%   The learner's tree as graph(Nodes, Edges) (node(Id, test|leaf, Label),
%   edge(From, To, yes|no)); graph([], []) for a learner without a tree.

engine_graph(KB, Graph) :-
    engine_learner(KB, Learner),
    (   capable(KB, graph)
    ->  learner_hook(learner_graph(Learner, KB, Graph))
    ;   Graph = graph([], [])
    ).

%!  engine_knowledge(+KB, -Terms:list) is det.
%
%   The learner's knowledge as a list of terms ([] for a learner that does not list it).

engine_knowledge(KB, Terms) :-
    engine_learner(KB, Learner),
    (   capable(KB, knowledge)
    ->  learner_hook(learner_knowledge(Learner, KB, Terms))
    ;   Terms = []
    ).

%!  engine_size(+KB, -Size) is det.
%
%   Size is size(Learner, Positions, Details): memory in the paper's positions and the
%   learner's own counts (Details, a list of Key=Value).

engine_size(KB, size(Learner, Positions, Details)) :-
    engine_learner(KB, Learner),
    (   capable(KB, size)
    ->  learner_hook(learner_size(Learner, KB, size(Positions, Details)))
    ;   Positions = 0, Details = []
    ).

%!  engine_snapshot(+KB, -Snapshot) is det.
%!  engine_restore(+KB, +Snapshot) is det.
%
%   Save and restore what an evaluation may disturb: working memory, the necessity units,
%   the last step, the random stream and the learner's episode state. The learned knowledge
%   itself is not part of it (evaluating must not change it in the first place).

engine_snapshot(KB, snapshot(Memory, Units, Eng, LearnerSnap)) :-
    engine_learner(KB, Learner),
    wm_state(KB, Memory),
    motivation_outputs(KB, Units),
    eng(KB, Eng),
    (   capable(KB, snapshot)
    ->  learner_hook(learner_snapshot(Learner, KB, LearnerSnap))
    ;   LearnerSnap = none
    ).

engine_restore(KB, snapshot(Memory, Units, Eng, LearnerSnap)) :-
    engine_learner(KB, Learner),
    wm_set_state(KB, Memory),
    motivation_set_outputs(KB, Units),
    set_eng(KB, Eng),
    (   capable(KB, snapshot)
    ->  learner_hook(learner_resume(Learner, KB, LearnerSnap))
    ;   true
    ).

%!  engine_keep(+KB, +Slot) is det.
%!  engine_resume(+KB, +Slot) is det.
%
%   engine_snapshot/2 kept in KB's record under the atom Slot, and restored from it (the
%   slot is forgotten). What Python uses: the snapshot never crosses the bridge.

engine_keep(KB, Slot) :-
    must_be(atom, Slot),
    engine_snapshot(KB, Snapshot),
    kb_get(KB, kept, Kept),
    kb_set(KB, kept, [Slot-Snapshot|Kept]).

engine_resume(KB, Slot) :-
    must_be(atom, Slot),
    kb_get(KB, kept, Kept0),
    (   selectchk(Slot-Snapshot, Kept0, Kept)
    ->  engine_restore(KB, Snapshot),
        kb_set(KB, kept, Kept)
    ;   existence_error(engine_snapshot, Slot)
    ).

%!  engine_policy_info(+KB, -Info:list) is det.
%
%   What a policy of KB's learner is tied to in the domain, Key(Value) terms written in the
%   policy's header (engine_policy/3) and compared with the loaded domain's when a policy is
%   read (policy.pl): the learner's learner_policy_info/3 (a relational learner: its
%   relations and language bias, the same in every world of a family, so its policy loads
%   in any of them), else [features(Features), responses(Responses)]. Each Key(Value) has
%   one argument.

engine_policy_info(KB, Info) :-
    run(KB, run(Learner, _, Features, Responses, _, _, _, _, _, Caps)),
    (   memberchk(policy_info, Caps)
    ->  learner_hook(learner_policy_info(Learner, KB, Info))
    ;   Info = [features(Features), responses(Responses)]
    ).

%!  engine_policy(+KB, +Header:text, -Text:string) is det.
%
%   Text is KB's learned knowledge as a policy file: a comment, relrl_policy(Learner, Info)
%   with what the policy is tied to in the domain (engine_policy_info/2), then the learner's
%   own clauses. Plain swipl consults the file; relrl reads it back as data (policy.pl).
%   Python writes Text to disk through relrl's one writer (atomic, never through a link).

engine_policy(KB, Header, Text) :-
    must_be(text, Header),
    engine_learner(KB, Learner),
    (   capable(KB, policy)
    ->  true
    ;   throw(error(learner_capability(Learner, policy), _))
    ),
    engine_policy_info(KB, Info),
    with_output_to(string(Text),
                   (   current_output(S),
                       write_policy(S, KB, Learner, Info, Header)
                   )).

write_policy(S, KB, Learner, Info, Header) :-
    split_string(Header, "\n", "", Lines),
    forall(member(L, Lines), format(S, "% ~w~n", [L])),
    format(S, "% Consult in plain swipl, or load with: relrl shell DOMAIN.pl --policy FILE~n",
           []),
    format(S, "% relrl reads this file as data: a directive or a foreign clause is refused.~n~n",
           []),
    portray_clause(S, relrl_policy(Learner, Info)),
    nl(S),
    learner_hook(learner_save(Learner, KB, S)).
