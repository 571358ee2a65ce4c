:- module(relrl_gateway,
          [ gw_run/2,             % :Goal, -Result
            gw_step/14,           % +KB, +Percepts, +Emitted, +Mode, +Want, -Result,
                                  % -Code, -Necessity, -Outputs, -Reward, -Reinforced,
                                  % -Mask, -Action, -Extras
            python_api/1,         % ?PredicateIndicator
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
:- use_module(engine, [engine_park/0]).
:- use_module(state, [state_touch/0]).

/** <module> What relrl's Python calls

The Python gateway (relrl/bridge/calls.py) calls only the predicates of this module, each
through the guard (guard.pl: once, exceptions as result terms, halt cancelled):

  - gw_run/2 runs a goal of a knowledge base or of python_api/1;
  - gw_step/14 is the control step (relrl_engine:engine_step/6), its result spread over
    output arguments that Python reads without decoding a term;
  - gw_answer/4 (toplevel.pl) is a user's query, one answer at a time, for relrl shell and
    KnowledgeBase.query/2 alike.

python_api/1 is the exact contract between relrl's Python and its Prolog: nothing else of
relrl's Prolog is reachable from Python, tests included. A knowledge base's own predicates
(the user's domain) always are.

Every call but a step first puts the random stream of the knowledge base that stepped last
away (engine_park/0): a user's query or a loaded file that draws random numbers draws from
none of the agents' streams. A call that may change the domain's rules (a goal of a
knowledge base, a user's query, loading a file) also makes the next step check which facts
it may read straight off working memory (relrl_state:state_touch/0).
*/

:- meta_predicate gw_run(0, -), api_call(0).

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

%   A goal of a knowledge-base module or of python_api/1; anything else is refused.
api_call(Goal) :-
    engine_park,
    strip_module(Goal, M, G),
    (   callable(G),
        functor(G, Name, Arity),
        (   kb_module(M)
        ->  state_touch
        ;   python_api(M:Name/Arity)
        )
    ->  call(Goal)
    ;   functor(G, Name, Arity),
        permission_error(call, private_predicate, M:Name/Arity)
    ).

%!  python_api(?PI) is nondet.
%
%   The predicates of relrl's Prolog that Python may call through gw_run/2, as
%   Module:Name/Arity. Everything else is private.

python_api(relrl_engine:engine_configure/4).
python_api(relrl_engine:engine_step/6).
python_api(relrl_engine:engine_end_episode/1).
python_api(relrl_engine:engine_explain/3).
python_api(relrl_engine:engine_text/2).
python_api(relrl_engine:engine_graph/2).
python_api(relrl_engine:engine_knowledge/2).
python_api(relrl_engine:engine_size/2).
python_api(relrl_engine:engine_policy/3).
python_api(relrl_engine:engine_keep/2).
python_api(relrl_engine:engine_resume/2).
python_api(relrl_engine:engine_reseed/2).
python_api(relrl_engine:engine_responses/2).
python_api(relrl_engine:engine_necessities/2).
python_api(relrl_engine:engine_learner/2).
python_api(relrl_engine:engine_relational_state/2).
python_api(relrl_policy:policy_learner/2).
python_api(relrl_policy:policy_load/2).
python_api(relrl_policy:policy_max_number/1).
python_api(relrl_memory:wm_insert/2).
python_api(relrl_memory:wm_elements/2).
python_api(relrl_memory:wm_clear/1).
python_api(relrl_memory:wm_clock/2).
python_api(relrl_memory:wm_set_span/2).
python_api(relrl_state:state_code/2).
python_api(relrl_state:state_terms/2).
python_api(relrl_state:state_decode/3).
python_api(relrl_state:state_encode/3).
python_api(relrl_state:state_features/2).
python_api(relrl_responses:allowed_responses/2).
python_api(relrl_declarations:necessity_inputs/3).
python_api(relrl_check:check_domain/2).
python_api(relrl_check:rule_listing/2).
python_api(relrl_check:bias_listing/2).
python_api(relrl_percepts:world_problems/3).
python_api(relrl_percepts:unread_percepts/3).
python_api(relrl_world:world_episodes/3).
python_api(relrl_world:world_info/2).
python_api(relrl_world:world_task/3).
python_api(relrl_world:world_verify/5).
python_api(relrl_world:world_for_task/2).
python_api(relrl_world_check:world_problems/2).
python_api(relrl_gateway:gw_new_kb/1).
python_api(relrl_gateway:gw_drop_kb/1).
python_api(relrl_gateway:gw_load/3).
python_api(relrl_gateway:gw_findall/3).
python_api(relrl_gateway:gw_parse/3).
python_api(relrl_gateway:gw_take_abort/1).
python_api(relrl_gateway:gw_answer_again/1).

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
