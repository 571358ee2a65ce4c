:- module(relrl_stepbench,
          [ stepbench_load/2,     % +File, -Recording
            stepbench_replay/3,   % +Recording, +Options, -Figures
            stepbench_main/0
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(option)).
:- use_module(library(pairs)).
:- use_module(library(statistics)).
:- use_module(library(http/json)).
:- use_module('../prolog/gateway').
:- use_module('../prolog/engine').

/** <module> The Prolog side of a control step, measured alone

A benchmark tool, not part of the knowledge layer. A *recording* of a run (written by
relrl/stepbench.py from a seeded run of an agent on the simulator) lists, step by step, the
percepts, the index of the response emitted at the previous step, the step's mode and what
engine_step/6 returned. This module replays it in plain swipl: it loads the recorded domain
into a knowledge base as relrl's gateway does, configures the engine with the recorded
learner, parameters and seed, and calls engine_step/6 once per recorded step — the knowledge
side of the robot's control step without Python and without the bridge.

Every replayed step must return exactly what the recording says (state code, necessity,
unit outputs, reward, allowed responses, the learner's choice); the first difference is an
error. So the figures are of the same decisions the Python run made.

Figures (per timed step; the warm-up steps are replayed untimed first): wall-clock and CPU
microseconds and inferences, net of the replay loop's own cost (measured by the same loop
with engine_step/6 left out), both with engine_step/6 called directly and through the
gateway's guarded call (gw_step/14, what Python calls; its time limit is Python's). With profile(true), SWI-Prolog's
profiler runs over the timed steps and the figures include each predicate's share of the
time and its calls per step.

    swipl -g relrl_stepbench:stepbench_main -t halt bench/stepbench.pl -- REC [--passes N]
          [--profile] [--top N]

prints the figures as one JSON object (relrl bench --prolog-step runs it).
*/

%!  stepbench_load(+File, -Recording) is det.
%
%   Read a recording, as data (nothing in it is run), and keep its events in this module's
%   database (as Python's gateway keeps recurring percept lists: a step copies its terms
%   onto the stacks, and the recording is no live data for the garbage collector).
%   Recording is recording(Domain, Learner, Params, Seed, Warmup, Events), Events the
%   number of events: s(Percepts, Emitted, Mode, Expected) terms and end_episode.
%
%   @error domain_error(stepbench_term, T) for a term that is not part of a recording.

:- dynamic event_/2.                % N, Event (1-based, in order)

stepbench_load(File, recording(Domain, Learner, Params, Seed, Warmup, Events)) :-
    retractall(event_(_, _)),
    setup_call_cleanup(
        open(File, read, S, [encoding(utf8)]),
        (   read_term(S, Header, []),
            (   Header = stepbench(Domain, Learner, Params, Seed, Warmup)
            ->  must_be(atom, Learner),
                must_be(list, Params),
                must_be(nonneg, Warmup)
            ;   domain_error(stepbench_recording, File)
            ),
            load_events(S, 0, Events)
        ),
        close(S)).

load_events(S, N0, N) :-
    read_term(S, T, []),
    (   T == end_of_file
    ->  N = N0
    ;   check_event(T),
        N1 is N0 + 1,
        assertz(event_(N1, T)),
        load_events(S, N1, N)
    ).

check_event(end_episode) :- !.
check_event(s(Percepts, Emitted, Mode, r(_, _, _, _, _, _, _))) :-
    is_list(Percepts), ground(Percepts), integer(Emitted), atom(Mode),
    !.
check_event(T) :-
    domain_error(stepbench_term, T).

%!  stepbench_replay(+Recording, +Options, -Figures:dict) is det.
%
%   Replay the loaded Recording (stepbench_load/2), checking every step, and measure it.
%   Options: passes(N) (default 3: each pass starts the engine afresh and replays the whole
%   recording; each figure is its median over the passes), profile(Bool) (default false),
%   top(N) (predicates listed in the profile, default 25).
%
%   @error stepbench_mismatch(Step, Expected, Got) when a replayed step differs from the
%   recording.

stepbench_replay(recording(Domain, Learner, Params, Seed, Warmup, Events), Options,
                 Figures) :-
    option(passes(Passes), Options, 3),
    must_be(positive_integer, Passes),
    option(profile(Profile), Options, false),
    option(top(Top), Options, 25),
    kb_for(Domain, KB),
    warmup_end(Warmup, 0, Events, Last),
    First is Last + 1,
    aggregate_all(count, ( between(First, Events, N), event_(N, s(_, _, _, _)) ), Steps),
    (   Steps > 0
    ->  true
    ;   domain_error(stepbench_timed_steps, Steps)
    ),
    Setup = setup(KB, Learner, Params, Seed, Last),
    Timed = First-Events,
    findall(P, ( between(1, Passes, _),
                 pass(Setup, Timed, direct, P) ), Direct),
    findall(P, ( between(1, Passes, _),
                 pass(Setup, Timed, gateway, P) ), Gateway),
    findall(P, ( between(1, Passes, _),
                 pass(Setup, Timed, overhead, P) ), Overhead),
    median_pass(Direct, D),
    median_pass(Gateway, G),
    median_pass(Overhead, O),
    per_step(D, O, Steps, DirectFig),
    per_step(G, O, Steps, GatewayFig),
    LoopUs is 1e6 * O.wall / Steps,
    Figures0 = _{learner:Learner, domain:Domain, seed:Seed, warmup:Warmup,
                 steps:Steps, passes:Passes, direct:DirectFig, gateway:GatewayFig,
                 loop_us_per_step:LoopUs},
    (   Profile == true
    ->  ProfilePasses is max(4, min(200, ceiling(1.5 / max(D.cpu, 0.001)))),
        profile_timed(Setup, Timed, Steps, ProfilePasses, Top, ProfileFig),
        Figures = Figures0.put(profile, ProfileFig)
    ;   Figures = Figures0
    ).

kb_for(Domain, KB) :-
    relrl_gateway:gw_new_kb(KB),
    relrl_gateway:gw_load(Domain, KB, Problems),
    (   member(problem(error, F, L, M), Problems)
    ->  throw(error(stepbench_domain(F:L, M), _))
    ;   true
    ).

%   Last is the number of the event of the Warmup-th step (0 for none).
warmup_end(0, N, _, N) :- !.
warmup_end(W, N0, Events, Last) :-
    N0 < Events,
    !,
    N is N0 + 1,
    (   event_(N, s(_, _, _, _))
    ->  W1 is W - 1
    ;   W1 = W
    ),
    warmup_end(W1, N, Events, Last).
warmup_end(W, _, _, _) :-
    domain_error(stepbench_warmup, W).

%   One pass: the engine afresh, the warm-up, then the timed steps (How: direct, gateway,
%   or overhead — the loop alone). pass{wall, cpu, inferences} in seconds and counts.
pass(setup(KB, Learner, Params, Seed, Last), First-Events, How,
     pass{wall:Wall, cpu:Cpu, inferences:Inf}) :-
    relrl_engine:engine_configure(KB, Learner, Params, Seed),
    replay(1, Last, KB, direct),
    garbage_collect,
    statistics(inferences, Inf0),
    statistics(cputime, C0),
    get_time(T0),
    replay(First, Events, KB, How),
    get_time(T1),
    statistics(cputime, C1),
    statistics(inferences, Inf1),
    Wall is T1 - T0,
    Cpu is C1 - C0,
    Inf is Inf1 - Inf0.

%   Events From..To replayed in a failure-driven loop: each step's terms are copied from
%   the database and freed after it, as in a gateway call.
replay(From, To, KB, How) :-
    (   between(From, To, N),
        event_(N, E),
        (   E == end_episode
        ->  relrl_engine:engine_end_episode(KB)
        ;   replay_step(How, KB, E, N)
        ),
        fail
    ;   true
    ).

%   I is the event's number (in messages).
replay_step(direct, KB, s(Percepts, Emitted, Mode, Expected), I) :-
    relrl_engine:engine_step(KB, Percepts, Emitted, Mode, [], Out),
    same(I, Expected, Out).
replay_step(gateway, KB, s(Percepts, Emitted, Mode, Expected), I) :-
    relrl_gateway:gw_step(KB, Percepts, Emitted, Mode, [], Result,
                          Code, N, Ys, Reward, Reinforced, Mask, Action, Extras),
    (   Result == true
    ->  same(I, Expected, step(Code, N, Ys, Reward, Reinforced, Mask, Action, Extras))
    ;   throw(error(stepbench_step(I, Result), _))
    ).
replay_step(overhead, _, s(_, _, _, r(C, N, Ys, R, Rf, M, A)), I) :-
    same(I, r(C, N, Ys, R, Rf, M, A), step(C, N, Ys, R, Rf, M, A, [])).

same(I, r(Code, N, Ys, Reward, Reinforced, Mask, Action), Out) :-
    (   Out = step(Code1, N1, Ys1, Reward1, Reinforced1, Mask1, Action1, _),
        Code1 == Code, N1 == N, Ys1 == Ys, Reward1 == Reward,
        Reinforced1 == Reinforced, Mask1 == Mask, Action1 == Action
    ->  true
    ;   throw(error(stepbench_mismatch(I, r(Code, N, Ys, Reward, Reinforced, Mask,
                                            Action), Out), _))
    ).

%   The median of each figure over the passes (each on its own: the wall clock of a busy
%   machine moves more than its CPU time).
median_pass(Passes, pass{wall:Wall, cpu:Cpu, inferences:Inf}) :-
    median_of(wall, Passes, Wall),
    median_of(cpu, Passes, Cpu),
    median_of(inferences, Passes, Inf).

median_of(Key, Passes, Median) :-
    maplist(get_dict(Key), Passes, Values),
    msort(Values, Sorted),
    length(Sorted, L),
    Mid is L // 2,
    nth0(Mid, Sorted, Median).

per_step(P, O, Steps, _{us_per_step:Us, cpu_us_per_step:CpuUs,
                        inferences_per_step:Inf}) :-
    Us is 1e6 * (P.wall - O.wall) / Steps,
    CpuUs is 1e6 * (P.cpu - O.cpu) / Steps,
    Inf is (P.inferences - O.inferences) / Steps.

%   ---- The profile -------------------------------------------------------------------------

%   The profiler runs over the timed steps only (off during the warm-up) of Passes passes
%   (enough for about 1.5 s of samples).
%   Per predicate: its share of the time with what it calls (cumulative) and alone (self),
%   in percent, and how often it is entered per step (a recursive predicate's calls to
%   itself are not counted).
profile_timed(setup(KB, Learner, Params, Seed, Last), First-Events, Steps, Passes, Top,
              _{passes:Passes, samples:Samples, ticks:Ticks, predicates:Rows}) :-
    reset_profiler,
    forall(between(1, Passes, _),
           ( relrl_engine:engine_configure(KB, Learner, Params, Seed),
             replay(1, Last, KB, direct),
             profiler(_, cputime),
             replay(First, Events, KB, direct),
             profiler(_, false) )),
    profile_data(Data),
    Samples = Data.summary.samples,
    Ticks = Data.summary.ticks,
    Calls is Passes * Steps,
    findall(Row, profile_row(Data.nodes, Ticks, Calls, Row), Rows0),
    sort(cumulative, @>=, Rows0, Rows1),
    length(Rows1, NRows),
    Keep is min(Top, NRows),
    length(Rows, Keep),
    append(Rows, _, Rows1).

profile_row(Nodes, Ticks, Steps, _{predicate:Name, cumulative:Cum, self:Self,
                                    calls_per_step:PerStep}) :-
    Ticks > 0,
    member(Node, Nodes),
    Node.ticks_self + Node.ticks_siblings > 0,
    format(string(Name), "~q", [Node.predicate]),
    Cum is 100 * (Node.ticks_self + Node.ticks_siblings) / Ticks,
    Self is 100 * Node.ticks_self / Ticks,
    PerStep is Node.call / Steps.

%   ---- Command line ------------------------------------------------------------------------

%!  stepbench_main is det.
%
%   The command line: stepbench.pl -- RECORDING [--passes N] [--profile] [--top N]; prints
%   the figures as JSON on standard output.

stepbench_main :-
    current_prolog_flag(argv, Argv),
    argv_options(Argv, Positional, Opts),
    (   Positional = [File]
    ->  true
    ;   throw(error(stepbench_usage(Argv), _))
    ),
    stepbench_load(File, Recording),
    option(passes(Passes), Opts, 3),
    option(top(Top), Opts, 25),
    (   option(profile(true), Opts)
    ->  Profile = true
    ;   Profile = false
    ),
    stepbench_replay(Recording, [passes(Passes), profile(Profile), top(Top)], Figures),
    json_write_dict(current_output, Figures, [width(0)]),
    nl.

:- multifile prolog:error_message//1.

prolog:error_message(stepbench_mismatch(I, Expected, Got)) -->
    [ 'step ~w of the recording: the engine returned ~q, the recording says ~q'-
      [I, Got, Expected] ].
prolog:error_message(stepbench_step(I, Result)) -->
    [ 'step ~w of the recording: the gateway call gave ~q'-[I, Result] ].
prolog:error_message(stepbench_domain(Where, Message)) -->
    [ 'the recording''s domain does not load: ~w: ~w'-[Where, Message] ].
prolog:error_message(stepbench_usage(Argv)) -->
    [ 'usage: stepbench.pl -- RECORDING [--passes N] [--profile] [--top N] (got ~q)'-
      [Argv] ].
