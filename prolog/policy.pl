:- module(relrl_policy,
          [ policy_learner/2,     % +File, -Learner
            policy_load/2         % +KB, +File
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(engine).

/** <module> Reading a saved policy as data

A policy file (the text of engine_policy/3) is Prolog that plain swipl can consult, but relrl
never consults it: a policy is data labs exchange, and loading one must never run anything.
This module reads it term by term with read_term/3 and accepts only

  - first, relrl_policy(Learner, Info), Info listing the features and responses of the
    domain it was learned in (they must be the loaded domain's);
  - then terms the learner declares its own (learner_policy_term/2), which the learner
    rebuilds its knowledge from (learner_restore/3) after checking them.

Anything else — a directive, a clause of another predicate, a syntax error, a policy of
another learner or another domain — raises

    error(relrl_policy_error(File, Line, Message), _)

naming the file and the line, and the knowledge base is left as it was.
*/

%!  policy_learner(+File, -Learner) is det.
%
%   Learner is the learner that saved the policy File (read from its first term).
%
%   @error relrl_policy_error(File, Line, Message) if File is not a relrl policy.

policy_learner(File, Learner) :-
    setup_call_cleanup(
        open_policy(File, S),
        header(File, S, relrl_policy(Learner, _), _),
        close(S)).

%!  policy_load(+KB, +File) is det.
%
%   Replace the learned knowledge of KB's learner by the policy in File, read as data.
%
%   @error relrl_policy_error(File, Line, Message) for anything that is not this learner's
%          policy for this domain.

policy_load(KB, File) :-
    setup_call_cleanup(
        open_policy(File, S),
        read_policy(File, S, Header, Line0, Terms),
        close(S)),
    Header = relrl_policy(Learner, Info),
    engine_learner(KB, Configured),
    (   Learner == Configured
    ->  true
    ;   policy_error(File, Line0, "the policy was learned by ~q, not by ~q", [Learner, Configured])
    ),
    check_info(KB, File, Line0, Info),
    maplist(check_term(File, Learner), Terms),
    pairs_values_(Terms, Values),
    catch(learner_restore_(Learner, KB, Values), error(Formal, _),
          restore_error(File, Formal)).

learner_restore_(Learner, KB, Values) :-
    (   relrl_engine:learner_restore(Learner, KB, Values)
    ->  true
    ;   existence_error(policy_restore, Learner)
    ).

open_policy(File, S) :-
    (   exists_file(File)
    ->  open(File, read, S, [encoding(utf8)])
    ;   policy_error(File, 0, "no such policy file", [])
    ).

pairs_values_([], []).
pairs_values_([_-V|T], [V|Vs]) :- pairs_values_(T, Vs).

%   The first term, which must be the header.
header(File, S, Header, Line) :-
    read_one(File, S, T, Line),
    (   T = relrl_policy(Learner, Info), atom(Learner), is_list(Info)
    ->  Header = T
    ;   T == end_of_file
    ->  policy_error(File, Line, "empty: not a relrl policy", [])
    ;   policy_error(File, Line, "not a relrl policy (its first term must be relrl_policy/2)",
                     [])
    ).

read_policy(File, S, Header, Line0, Terms) :-
    header(File, S, Header, Line0),
    read_rest(File, S, Terms).

read_rest(File, S, Terms) :-
    read_one(File, S, T, Line),
    (   T == end_of_file
    ->  Terms = []
    ;   Terms = [Line-T|Rest],
        read_rest(File, S, Rest)
    ).

read_one(File, S, T, Line) :-
    catch(read_term(S, T, [term_position(Pos), syntax_errors(error)]), E,
          read_error(File, S, E)),
    (   nonvar(Pos)
    ->  stream_position_data(line_count, Pos, Line)
    ;   line_count(S, Line)
    ).

read_error(File, S, E) :-
    (   E = error(syntax_error(What), Context)
    ->  (   Context = stream(_, Line, _, _)
        ->  true
        ;   Context = file(_, Line, _, _)
        ->  true
        ;   line_count(S, Line)
        ),
        policy_error(File, Line, "syntax error: ~w", [What])
    ;   E = error(Formal, _),
        memberchk(Formal, [io_error(_, _), representation_error(_)])
    ->  line_count(S, Line),
        policy_error(File, Line, "cannot read: ~q (not a text policy file?)", [Formal])
    ;   throw(E)
    ).

check_info(KB, File, Line, Info) :-
    engine_config(KB, features, Features),
    engine_config(KB, responses, Responses),
    (   memberchk(features(F), Info), memberchk(responses(R), Info)
    ->  true
    ;   policy_error(File, Line, "relrl_policy/2 does not list the domain's features and \c
                     responses (a policy of an older relrl?)", [])
    ),
    (   F =@= Features
    ->  true
    ;   first_difference(F, Features, Theirs, Ours),
        policy_error(File, Line, "learned for another domain: its features differ from the \c
                     loaded domain's (~q in the policy, ~q in the domain)", [Theirs, Ours])
    ),
    (   R =@= Responses
    ->  true
    ;   first_difference(R, Responses, Theirs, Ours),
        policy_error(File, Line, "learned for another domain: its responses differ from the \c
                     loaded domain's (~q in the policy, ~q in the domain)", [Theirs, Ours])
    ).

first_difference([X|Xs], [Y|Ys], A, B) :-
    (   X =@= Y
    ->  first_difference(Xs, Ys, A, B)
    ;   A = X, B = Y
    ).
first_difference([], [Y|_], nothing, Y).
first_difference([X|_], [], X, nothing).
first_difference([], [], nothing, nothing).

check_term(File, Learner, Line-T) :-
    (   T = (:- _)
    ->  policy_error(File, Line, "a directive in a policy file is refused (a policy is \c
                     data and never runs anything)", [])
    ;   relrl_engine:learner_policy_term(Learner, T)
    ->  true
    ;   (   T = (Head :- _)
        ->  true
        ;   Head = T
        ),
        (   callable(Head)
        ->  functor(Head, Name, Arity),
            policy_error(File, Line, "~q is not part of a ~q policy (refused)",
                         [Name/Arity, Learner])
        ;   policy_error(File, Line, "~q is not part of a ~q policy (refused)", [Head, Learner])
        )
    ).

restore_error(File, Formal) :-
    (   memberchk(Formal, [type_error(_, _), domain_error(_, _), existence_error(_, _),
                           instantiation_error])
    ->  message_to_codes_(Formal, Text),
        policy_error(File, 0, "bad policy: ~s", [Text])
    ;   throw(error(Formal, _))
    ).

message_to_codes_(Formal, Codes) :-
    '$messages':translate_message(error(Formal, _), Lines, []),
    with_output_to(codes(Codes), print_message_lines(current_output, '', Lines)).

policy_error(File, Line, Format, Args) :-
    format(string(Message), Format, Args),
    throw(error(relrl_policy_error(File, Line, Message), _)).
