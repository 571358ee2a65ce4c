/*  plunit tests of reading a policy as data (prolog/policy.pl) and of the learners' checks
    of a policy as a whole before they restore it (etg.pl, contingency.pl). Run from pytest
    (tests/prolog/test_plunit.py) or:
        swipl -g run_tests -t halt prolog/relrl.pl tests/prolog/test_policy.plt
*/
:- use_module(library(plunit)).
:- use_module(library(lists)).
:- use_module('../../prolog/relrl').
:- use_module('../../prolog/gateway').
:- use_module('../../prolog/policy').

tiny_kb(KB, Learner, Params) :-
    relrl_gateway:gw_new_kb(KB),
    module_property(relrl, file(RelrlFile)),
    file_directory_name(RelrlFile, Dir),
    atomic_list_concat([Dir, '/../tests/data/tiny.pl'], Path),
    relrl_gateway:gw_load(Path, KB, Problems),
    assertion(Problems == []),
    relrl_engine:engine_configure(KB, Learner, Params, 0).

etg_kb(KB) :-
    tiny_kb(KB, etg, [alpha=0.5, gamma=0.9, epsilon=0.0, q_init=0.0, split_threshold=1.0,
                      reward_positive=10.0, reward_negative= -1.0]).

contingency_kb(KB) :-
    tiny_kb(KB, contingency, [default_fitness=1.0, influence=0.5, min_fitness=0.05,
                              max_fitness=10.0, reward_positive=10.0,
                              reward_negative= -1.0]).

tests([stimulus(light), stimulus(dark), stimulus(food)]).

%   Restore the ETG terms Nodes (with the domain's tests); Message is the refusal's text,
%   Culprit the term it names.
etg_refusal(Nodes, Culprit, Message) :-
    etg_kb(KB),
    tests(Tests),
    catch(relrl_engine:learner_restore(etg, KB, [etg_tests(Tests)|Nodes]),
          error(relrl_policy_refused(Culprit, Message), _), true).

% ---------------------------------------------------------------------------------------
:- begin_tests(policy_numbers).

test(in_range) :-
    forall(member(X, [0, -3, 1.0e15, -1.0e15, 1000000000000000, 29.45]),
           policy_number(t, "Q", X)).

test(too_large, [error(relrl_policy_refused(t, Message))]) :-
    policy_number(t, "Q", 1.0000001e15),
    Message = _.

test(digits_shown_by_count, [Message == "Q (an integer of 401 digits) is out of range: a \c
                                        policy's values are finite numbers of magnitude at \c
                                        most 1e+15"]) :-
    X is 10^400,
    catch(policy_number(t, "Q", X), error(relrl_policy_refused(t, Message), _), true).

test(infinity_and_nan_refused) :-
    Inf is inf, NaN is nan,
    forall(member(X, [Inf, NaN]),
           catch(policy_number(t, "Q", X), error(relrl_policy_refused(t, _), _), true)),
    \+ catch(policy_number(t, "Q", Inf), error(relrl_policy_refused(_, _), _), fail).

test(not_a_number, [Message == "Q high is not a number"]) :-
    catch(policy_number(t, "Q", high), error(relrl_policy_refused(t, Message), _), true).

test(variables_shown_as_underscore, [Message == "look(_) is foreign"]) :-
    catch(policy_refuse(t, "~q is foreign", [look(_)]),
          error(relrl_policy_refused(t, Message), _), true).

:- end_tests(policy_numbers).

% ---------------------------------------------------------------------------------------
:- begin_tests(etg_policy_shape).

test(a_tree_restores) :-
    etg_kb(KB),
    tests(Tests),
    relrl_engine:learner_restore(etg, KB,
        [etg_tests(Tests),
         etg_node(0, test(0, stimulus(light), 1, 2)),
         etg_node(1, leaf(1, [e(b, 1.0, hunger), e(a, 2.0, hunger)])),
         etg_node(2, leaf(none, []))]),
    % entries put in decreasing Q, as the learner keeps them
    relrl_qtree:qtree(KB, T),
    relrl_qtree:qtree_leaf(T, 1, 1, Entries),
    assertion(Entries == [e(a, 2.0, hunger), e(b, 1.0, hunger)]).

test(id_out_of_range, [Message == "node id 1000000000 is out of range: this policy has 2 \c
                                   nodes, ids 0 to 1"]) :-
    etg_refusal([etg_node(0, test(0, stimulus(light), 1000000000, nil)),
                 etg_node(1000000000, leaf(none, []))], _, Message).

test(dangling_branch, [Message == "node 0's no-branch leads to node 5, which this policy \c
                                   does not hold (a dangling branch)"]) :-
    etg_refusal([etg_node(0, test(0, stimulus(light), 1, 5)),
                 etg_node(1, leaf(none, []))], _, Message).

test(back_to_the_root, [Culprit-Message == etg_node(1, test(1, stimulus(dark), 0, nil))-
                        "node 1's yes-branch leads back to the root (a cycle)"]) :-
    etg_refusal([etg_node(0, test(0, stimulus(light), 1, nil)),
                 etg_node(1, test(1, stimulus(dark), 0, nil))], Culprit, Message).

test(a_cycle_below_the_root, [Message == "node 1 cannot be reached from the root (node 0): \c
                                          the nodes do not form one tree"]) :-
    etg_refusal([etg_node(0, leaf(none, [])),
                 etg_node(1, test(1, stimulus(dark), 2, nil)),
                 etg_node(2, test(2, stimulus(food), 1, nil))], _, Message).

test(two_parents, [Message == "node 1 is reached from node 0 and from node 0: a node of a \c
                               tree has one parent"]) :-
    etg_refusal([etg_node(0, test(0, stimulus(light), 1, 1)),
                 etg_node(1, leaf(none, []))], _, Message).

test(twice, [Message == "node 0 is defined twice"]) :-
    etg_refusal([etg_node(0, leaf(none, [])), etg_node(0, leaf(none, []))], _, Message).

test(no_root, [Message == "no etg_node/2: a tree has at least its root, node 0"]) :-
    etg_refusal([], _, Message).

test(state_does_not_reach_its_leaf,
     [Message == "leaf 1: its state 0 does not reach it (the tests on the path from the \c
                  root disagree)"]) :-
    % leaf 1 is on the yes-branch of stimulus(light) (bit 0): state 0 does not have it
    etg_refusal([etg_node(0, test(0, stimulus(light), 1, nil)),
                 etg_node(1, leaf(0, []))], _, Message).

test(state_out_of_range) :-
    etg_refusal([etg_node(0, leaf(8, []))], _, Message),
    assertion(sub_string(Message, 0, _, _, "leaf 0: its state 8 is not a state")).

test(foreign_response, [Message == "leaf 0: halt is not a response of this domain"]) :-
    etg_refusal([etg_node(0, leaf(none, [e(halt, 1.0, hunger)]))], _, Message).

test(open_response, [Message == "leaf 0: look(_) is not a response of this domain"]) :-
    etg_refusal([etg_node(0, leaf(none, [e(look(_), 1.0, hunger)]))], _, Message).

test(foreign_necessity, [Message == "leaf 0: '<script>' is not a necessity of this domain \c
                                     (nor none)"]) :-
    etg_refusal([etg_node(0, leaf(none, [e(a, 1.0, '<script>')]))], _, Message).

test(q_out_of_range) :-
    etg_refusal([etg_node(0, leaf(none, [e(a, 1.0e300, hunger)]))], _, Message),
    assertion(sub_string(Message, _, _, _, "the Q of a 1.0e+300 is out of range")).

test(two_entries_for_one_action, [Message == "leaf 0 holds two entries for a under hunger"]) :-
    etg_refusal([etg_node(0, leaf(none, [e(a, 1.0, hunger), e(a, 2.0, hunger)]))], _,
                Message).

test(refused_leaves_the_tree_as_it_was) :-
    etg_kb(KB),
    tests(Tests),
    relrl_engine:learner_restore(etg, KB, [etg_tests(Tests),
                                           etg_node(0, leaf(3, [e(a, 1.0, hunger)]))]),
    catch(relrl_engine:learner_restore(etg, KB, [etg_tests(Tests),
                                                 etg_node(0, leaf(3, [e(halt, 1.0, hunger)]))]),
          error(relrl_policy_refused(_, _), _), true),
    relrl_qtree:qtree(KB, T),
    relrl_qtree:qtree_leaf(T, 0, Rep, Entries),
    assertion(Rep-Entries == 3-[e(a, 1.0, hunger)]).

:- end_tests(etg_policy_shape).

% ---------------------------------------------------------------------------------------
:- begin_tests(contingency_policy).

contingency_refusal(Rules, Message) :-
    contingency_kb(KB),
    catch(relrl_engine:learner_restore(contingency, KB, Rules),
          error(relrl_policy_refused(_, Message), _), true).

test(good_rules_restore, [Rules == [behaviour(state(1), a, hunger, 2.5)]]) :-
    contingency_kb(KB),
    relrl_engine:learner_restore(contingency, KB,
                                 [learned_behaviour(state(1), a, hunger, 2.5)]),
    relrl_contingency:contingency_rules(KB, Rules).

test(state_out_of_range) :-
    X is 10^40,
    contingency_refusal([learned_behaviour(state(X), a, hunger, 1.0)], Message),
    assertion(sub_string(Message, _, _, _, "is not a state of this domain")).

test(foreign_response, [Message == "halt is not a response of this domain"]) :-
    contingency_refusal([learned_behaviour(state(1), halt, hunger, 1.0)], Message).

test(foreign_antecedent) :-
    contingency_refusal([learned_behaviour(shell(rm), a, hunger, 1.0)], Message),
    assertion(sub_string(Message, 0, _, _, "shell(rm) is neither state(Code)")).

test(negative_fitness) :-
    contingency_refusal([learned_behaviour(state(1), a, hunger, -1.0)], Message),
    assertion(sub_string(Message, 0, _, _, "the fitness -1.0 is negative")).

test(learned_rule_twice) :-
    contingency_refusal([learned_behaviour(state(1), a, hunger, 1.0),
                         learned_behaviour(state(1), a, hunger, 2.0)], Message),
    assertion(sub_string(Message, 0, _, _, "this learned rule is given twice")).

:- end_tests(contingency_policy).

% ---------------------------------------------------------------------------------------
:- begin_tests(policy_once).

test(trees_are_declared_once) :-
    policy_once(tg_tree(_)),
    policy_once(ptg_tree(_)).

test(second_tree_named_at_its_line,
     [error(relrl_policy_error(f, 7, "a second tg_tree/1 (the first is on line 3): a policy \c
                                     holds one"))]) :-
    relrl_policy:once_only(f, tg_tree(_), [1-relrl_policy(tg, []), 3-tg_tree(leaf(1, 0.0, 0)),
                                          5-q(a, b, c), 7-tg_tree(leaf(1, 0.0, 0))]).

test(one_tree_passes) :-
    relrl_policy:once_only(f, tg_tree(_), [3-tg_tree(leaf(1, 0.0, 0)), 5-q(a, b, c)]).

:- end_tests(policy_once).
