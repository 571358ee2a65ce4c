/*  plunit tests of the knowledge layer. Run from pytest (tests/prolog/test_plunit.py) or:
        swipl -g run_tests -t halt prolog/relrl.pl tests/prolog/test_knowledge.plt
*/
:- use_module(library(plunit)).
:- use_module('../../prolog/relrl').
:- use_module('../../prolog/gateway').

fresh_kb(KB, File) :-
    relrl_gateway:gw_new_kb(KB),
    source_file_property(_, module(relrl)),     % loaded
    module_property(relrl, file(RelrlFile)),
    file_directory_name(RelrlFile, Dir),
    atomic_list_concat([Dir, '/../examples/domains/', File], Path),
    relrl_gateway:gw_load(Path, KB, Problems),
    assertion(Problems == []).

:- begin_tests(memory).

test(new_element_age_zero, [Age == 0]) :-
    relrl_gateway:gw_new_kb(KB),
    relrl_memory:wm_set_span(KB, 5),
    relrl_memory:wm_insert(KB, [see(face)]),
    relrl_memory:wm_element(KB, see(face), Age).

test(later_insertion_ages, [Ages == [0-see(toy), 1-see(face)]]) :-
    relrl_gateway:gw_new_kb(KB),
    relrl_memory:wm_set_span(KB, 5),
    relrl_memory:wm_insert(KB, [see(face)]),
    relrl_memory:wm_insert(KB, [see(toy)]),
    relrl_memory:wm_elements(KB, Ages).

test(expires_after_span, [Es == [0-c, 1-b]]) :-
    relrl_gateway:gw_new_kb(KB),
    relrl_memory:wm_set_span(KB, 1),
    relrl_memory:wm_insert(KB, [a]),
    relrl_memory:wm_insert(KB, [b]),
    relrl_memory:wm_insert(KB, [c]),
    relrl_memory:wm_elements(KB, Es).

test(reinsert_renews, [Es == [0-a, 1-b]]) :-
    relrl_gateway:gw_new_kb(KB),
    relrl_memory:wm_set_span(KB, 3),
    relrl_memory:wm_insert(KB, [a]),
    relrl_memory:wm_insert(KB, [b]),
    relrl_memory:wm_insert(KB, [a]),
    relrl_memory:wm_elements(KB, Es).

test(nonground_rejected, [error(instantiation_error)]) :-
    relrl_gateway:gw_new_kb(KB),
    relrl_memory:wm_insert(KB, [see(_)]).

test(bad_span, [error(type_error(nonneg, -1))]) :-
    relrl_gateway:gw_new_kb(KB),
    relrl_memory:wm_set_span(KB, -1).

test(isolated) :-
    relrl_gateway:gw_new_kb(A),
    relrl_gateway:gw_new_kb(B),
    relrl_memory:wm_insert(A, [see(face)]),
    \+ relrl_memory:wm_element(B, _, _).

:- end_tests(memory).

:- begin_tests(state).

test(codes_follow_declaration_order, [Fs = [stimulus(face), stimulus(object)|_]]) :-
    fresh_kb(KB, 'fruits.pl'),
    relrl_state:state_features(KB, Fs).

test(state_code_sum_of_powers, [Code == 8321]) :-   % 2^0 + 2^7 + 2^13
    fresh_kb(KB, 'fruits.pl'),
    relrl_memory:wm_insert(KB, [see(face), pose(face, frontal), at(centre)]),
    relrl_state:state_code(KB, Code).

test(decode_encode_roundtrip, [Terms == Expected]) :-
    fresh_kb(KB, 'fruits.pl'),
    relrl_memory:wm_insert(KB, [see(object), colour(object, red), hear(attention)]),
    relrl_state:state_code(KB, Code),
    relrl_state:state_decode(KB, Code, Terms),
    relrl_state:state_terms(KB, Expected),
    relrl_state:state_encode(KB, Terms, Code2),
    assertion(Code2 == Code).

test(decode_rejects_unknown_bits, [error(domain_error(state_code, _))]) :-
    fresh_kb(KB, 'fruits.pl'),
    relrl_state:state_decode(KB, 1048576, _).

test(fact_applied_to_stimulus) :-
    fresh_kb(KB, 'fruits.pl'),
    relrl_memory:wm_insert(KB, [see(face), pose(face, frontal)]),
    relrl_senses:perceived(KB, see, frontal(face)),
    \+ relrl_senses:perceived(KB, see, left_profile_1(face)).

:- end_tests(state).

:- begin_tests(responses).

test(constraint_forbids, [Rs == [look(centre), look(left), look(left_down), look(down),
                                 look(right_down), look(right)]]) :-
    fresh_kb(KB, 'fruits.pl'),
    relrl_memory:wm_insert(KB, [see(face)]),
    relrl_responses:allowed_responses(KB, Rs).

test(constraint_allows) :-
    fresh_kb(KB, 'fruits.pl'),
    relrl_memory:wm_insert(KB, [see(object), colour(object, red)]),
    relrl_responses:allowed_response(KB, name_object).

:- end_tests(responses).

:- begin_tests(check).

test(example_domains_valid, [P1-P2 == []-[]]) :-
    fresh_kb(A, 'fruits.pl'),
    fresh_kb(B, 'sis.pl'),
    relrl_check:check_domain(A, P1),
    relrl_check:check_domain(B, P2).

:- end_tests(check).

% ---------------------------------------------------------------------------------------
%   What a guarded call leaves behind: the caller's flag (false between calls), whatever
%   way the call ended. (Its time limit is armed and disarmed by the host: see
%   tests/relrl/test_deadline.py.)
caller_state(Active) :-
    relrl_guard:call_context(active, Active).

:- begin_tests(gateway_call).

ends(true, true).
ends(fail, false).
ends(throw(oops), error(oops, _)).
ends(relrl_guard:time_up(vtalrm), error(time_limit_exceeded, _)).
ends(halt, error(halt_called(goal), _)).
ends(relrl_guard:interrupt(usr1), error(interrupted, _)).

test(each_end_restores_the_caller, [Ends == [ok, ok, ok, ok, ok, ok]]) :-
    caller_state(Before),
    findall(Ok, ( ends(Goal, Expected),
                  relrl_guard:guarded(Goal, Result),
                  caller_state(After),
                  (   subsumes_term(Expected, Result), After == Before
                  ->  Ok = ok
                  ;   Ok = Goal-Result-After
                  ) ),
            Ends).

%   An inner call's error ends the inner call only; the outer call is still guarded after
%   it.
test(nested_calls, [Inner-Active-Outer == oops-true-true]) :-
    caller_state(Before),
    relrl_guard:guarded(( relrl_guard:guarded(throw(oops), error(Inner, _)),
                          user:caller_state(Active) ),
                        Outer),
    caller_state(After),
    assertion(After == Before).

%   The signals of the host's watchdog stop nothing between calls (one raised as a call
%   returned arrives when none runs).
test(signals_between_calls_do_nothing) :-
    relrl_guard:time_up(vtalrm),
    relrl_guard:interrupt(usr1).

%   Rendering a message or an answer as text may fail over to a plain rendering, but a
%   time limit, Ctrl-C or a resource error always reaches the caller (abort too: it cannot
%   be caught here to be checked).
test(text_rendering_lets_limits_through, [Passed == [time_limit_exceeded,
                                                     relrl_interrupted,
                                                     error(resource_error(memory), c)]]) :-
    findall(E, ( member(E, [time_limit_exceeded, relrl_interrupted,
                            error(resource_error(memory), c)]),
                 catch(relrl_guard:text_failed(E), E, true) ),
            Passed),
    \+ relrl_guard:text_failed(error(type_error(text, x), _)).

:- end_tests(gateway_call).

:- begin_tests(call_context).

%   The per-call context is one record: a key set is read back, the others keep their
%   values, and a key that is not the record's is refused.
test(one_record, [Got-After == (here:3)-Before]) :-
    findall(K-V, ( relrl_guard:call_context(K, V), K \== timeout_where ), Before),
    relrl_guard:call_context(timeout_where, Was),
    relrl_guard:set_call_context(timeout_where, here:3),
    relrl_guard:call_context(timeout_where, Got),
    findall(K-V, ( relrl_guard:call_context(K, V), K \== timeout_where ), After),
    relrl_guard:set_call_context(timeout_where, Was).

test(unknown_key, [error(domain_error(call_context_key, no_such_key))]) :-
    relrl_guard:set_call_context(no_such_key, 1).

test(the_ten_keys, [Keys == [active, halt, abort, timeout_where, answer_mode,
                             answer_again, random_owner, state_touch, watch, progress]]) :-
    findall(K, relrl_guard:call_context(K, _), Keys).

:- end_tests(call_context).
