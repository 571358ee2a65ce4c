:- module(relrl_gateway,
          [ gw_run/2,             % :Goal, -Result
            gw_step/14,           % +KB, +Percepts, +Emitted, +Mode, +Want, -Result,
                                  % -Code, -Necessity, -Outputs, -Reward, -Reinforced,
                                  % -Mask, -Action, -Extras
            python_api/2,         % ?Name, ?PredicateIndicator
            gw_api/1,             % -Pairs
            gw_findall/3,         % +Module, +Template, -List
            gw_parse/3            % +Module, +Text, -Terms
          ]).
:- use_module(library(error)).
:- use_module(library(apply)).
:- use_module(relrl).
:- use_module(declarations).
:- use_module(policy).
:- use_module(guard).
:- reexport(kb_load, [gw_new_kb/1, gw_drop_kb/1, gw_load/3]).
:- use_module(kb_load, [kb_module/1]).
:- reexport(toplevel).
:- reexport(guard, [gw_take_abort/1]).
:- use_module(engine, [engine_pause/0]).

/** <module> What relrl's Python calls

The Python gateway (relrl/bridge/calls.py) calls only the predicates of this module, each
through the guard (guard.pl: once, exceptions as result terms, halt cancelled):

  - gw_run/2 runs a goal of a knowledge base or of python_api/2;
  - gw_step/14 is the control step (relrl_engine:engine_step/6), its result spread over
    output arguments that Python reads without decoding a term;
  - gw_answer/4 (toplevel.pl) is a user's query, one answer at a time, for relrl shell and
    KnowledgeBase.query/2 alike.

python_api/2 is the exact contract between relrl's Python and its Prolog, and its one
source: Python asks for it (gw_api/1) when it starts and calls goals by their short names.
Nothing else of relrl's Prolog is reachable from Python, tests included. A knowledge base's
own predicates (the user's domain) always are.

Every call but a step first lets go of what the last step kept (relrl_engine:engine_pause/0:
the random stream of the knowledge base that stepped last, so that a user's query or a
loaded file that draws random numbers draws from none of the agents' streams; and the
check of which facts the next step may read straight off working memory).
*/

:- meta_predicate gw_run(0, -), api_call(0), gw_watched(+, 0).

%!  gw_run(:Goal, -Result) is det.
%
%   Run Goal once: Result is `true` (Goal's bindings are kept), `false` or
%   error(Kind, Message) (see relrl_guard:error_result/2).

gw_run(Goal, Result) :-
    guarded(api_call(Goal), Result).

%!  gw_step(+KB, +Percepts, +Emitted, +Mode, +Want, -Result, -Code, -Necessity,
%!          -Outputs, -Reward, -Reinforced, -Mask, -Action, -Extras) is det.
%
%   One control step: relrl_engine:engine_step(KB, Percepts, Emitted, Mode, Want, Out) run
%   as gw_run/2 runs a goal, with the fields of Out (step(Code, Necessity, Outputs, Reward,
%   Reinforced, Mask, Action, Extras)) as arguments of their own, read by Python with one
%   foreign call each. The outputs stay unbound unless Result is `true`. No random stream
%   is parked: the step swaps streams itself.

gw_step(KB, Percepts, Emitted, Mode, Want, Result,
        Code, Necessity, Outputs, Reward, Reinforced, Mask, Action, Extras) :-
    guarded(relrl_engine:engine_step(KB, Percepts, Emitted, Mode, Want, Out), Result),
    (   Result == true
    ->  Out = step(Code, Necessity, Outputs, Reward, Reinforced, Mask, Action, Extras)
    ;   true
    ).

%   A goal of a knowledge-base module or of python_api/2; anything else is refused.
api_call(Goal) :-
    engine_pause,
    strip_module(Goal, M, G),
    (   callable(G),
        functor(G, Name, Arity),
        (   kb_module(M)
        ->  true
        ;   python_api(_, M:Name/Arity)
        )
    ->  call(Goal)
    ;   functor(G, Name, Arity),
        permission_error(call, private_predicate, M:Name/Arity)
    ).

%!  gw_api(-Pairs:list) is det.
%
%   Pairs are Name-Module:Predicate/Arity for every python_api/2 entry: what Python asks
%   when it starts.

gw_api(Pairs) :-
    findall(Name-PI, python_api(Name, PI), Pairs).

%!  python_api(?Name, ?PI) is nondet.
%
%   The predicates of relrl's Prolog that Python may call through gw_run/2, as
%   Module:Name/Arity, each with the short name Python calls it by. Everything else is
%   private.

python_api(configure, relrl_engine:engine_configure/4).
python_api(end_episode, relrl_engine:engine_end_episode/1).
python_api(explain, relrl_engine:engine_explain/3).
python_api(text, relrl_engine:engine_text/2).
python_api(graph, relrl_engine:engine_graph/2).
python_api(knowledge, relrl_engine:engine_knowledge/2).
python_api(size, relrl_engine:engine_size/2).
python_api(policy, relrl_engine:engine_policy/3).
python_api(keep, relrl_engine:engine_keep/2).
python_api(resume, relrl_engine:engine_resume/2).
python_api(reseed, relrl_engine:engine_reseed/2).
python_api(responses, relrl_engine:engine_responses/2).
python_api(necessities, relrl_engine:engine_necessities/2).
python_api(relational_state, relrl_engine:engine_relational_state/2).
python_api(policy_learner, relrl_policy:policy_learner/2).
python_api(policy_load, relrl_policy:policy_load/2).
python_api(policy_max_number, relrl_policy:policy_max_number/1).
python_api(wm_insert, relrl_memory:wm_insert/2).
python_api(wm_elements, relrl_memory:wm_elements/2).
python_api(wm_clear, relrl_memory:wm_clear/1).
python_api(wm_clock, relrl_memory:wm_clock/2).
python_api(learners, relrl_learners:learner_catalogue/1).
python_api(state_code, relrl_state:state_code/2).
python_api(state_terms, relrl_state:state_terms/2).
python_api(state_decode, relrl_state:state_decode/3).
python_api(state_features, relrl_state:state_features/2).
python_api(allowed_responses, relrl_responses:allowed_responses/2).
python_api(necessity_inputs, relrl_declarations:necessity_inputs/3).
python_api(check_domain, relrl_check:check_domain/2).
python_api(rule_listing, relrl_check:rule_listing/2).
python_api(bias_listing, relrl_check:bias_listing/2).
python_api(world_problems, relrl_percept_check:world_problems/3).
python_api(unread_percepts, relrl_percept_check:unread_percepts/3).
python_api(world_episodes, relrl_world:world_episodes/3).
python_api(world_info, relrl_world:world_info/2).
python_api(world_task, relrl_world:world_task/3).
python_api(world_verify, relrl_world:world_verify/5).
python_api(world_reachable, relrl_world:world_reachable/5).
python_api(world_absent, relrl_world:world_absent/4).
python_api(world_for_task, relrl_world:world_for_task/2).
python_api(world_check, relrl_world_check:world_problems/2).
python_api(world_episodes_from, relrl_world:world_episodes_from/3).
python_api(world_read_states, relrl_world_states:world_read_states/4).
python_api(world_state_texts, relrl_world_states:world_state_texts/4).
python_api(watched, relrl_gateway:gw_watched/2).
python_api(new_kb, relrl_gateway:gw_new_kb/1).
python_api(drop_kb, relrl_gateway:gw_drop_kb/1).
python_api(load, relrl_gateway:gw_load/3).
python_api(findall, relrl_gateway:gw_findall/3).
python_api(parse, relrl_gateway:gw_parse/3).
python_api(take_abort, relrl_gateway:gw_take_abort/1).
python_api(api, relrl_gateway:gw_api/1).
python_api(answer_again, relrl_gateway:gw_answer_again/1).

%!  gw_watched(+Limit:number, :Goal) is semidet.
%
%   Goal, a goal Python may call (as gw_run/2 runs it), with the call's time limit counted
%   from the last progress mark (relrl_guard:progress_watch/2): a batch of a world's
%   episodes runs as long as it makes progress, a rule that loops is stopped after Limit
%   seconds.

gw_watched(Limit, Goal) :-
    progress_watch(Limit, api_call(Goal)).

%!  gw_findall(+Module, +Template, -List) is det.
%
%   List holds every declaration Template (e.g. stimulus(X)) of the knowledge base Module.

gw_findall(Module, Template, List) :-
    findall(Template, declared(Module, Template), List).

%!  gw_parse(+Module, +Text, -Terms:list) is det.
%
%   Terms are the comma-separated terms of Text, read with Module's operators. Reading
%   only: nothing in Text is run. A syntax error raises.

gw_parse(Module, Text, Terms) :-
    term_string(Term, Text, [module(Module)]),
    comma_list(Term, Terms).
