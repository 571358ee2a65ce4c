:- module(relrl_policy,
          [ policy_learner/2,     % +File, -Learner
            policy_load/2,        % +KB, +File
            policy_once/1,        % ?Template
            policy_refuse/3,      % +Term, +Format, +Args
            policy_number/3,      % +Term, +What, +Number
            policy_max_number/1   % -Max
          ]).
:- use_module(library(error)).
:- use_module(library(lists)).
:- use_module(library(apply)).
:- use_module(library(occurs)).
:- use_module(engine).
:- use_module(guard, [message_text/2]).

/** <module> Reading a saved policy as data

A policy file (the text of engine_policy/3) is Prolog that plain swipl can consult, but relrl
never consults it: a policy is data labs exchange, and loading one must never run anything.
This module reads it term by term with read_term/3 and accepts only

  - first, relrl_policy(Learner, Info), Info listing what the policy is tied to in the
    domain it was learned in (relrl_engine:engine_policy_info/2: its features and
    responses, or a relational learner's relations and language bias, rmodes and rconsts);
    they must be the
    loaded domain's;
  - then terms the learner declares its own (learner_policy_term/2), which the learner
    rebuilds its knowledge from (learner_restore/3) after checking them as a whole.

Every number in the file must be an integer or a finite float (no infinity, NaN or rational
such as 1r3). A learner checks the rest before it changes anything: node ids in range, a
tree (one root, one parent per node, no cycle, no stray node), responses and necessities of
the loaded domain, values finite and at most policy_max_number/1 in magnitude (so that no
update can overflow). It refuses with policy_refuse/3, naming the term at fault; this
module finds the term's line.

Anything else — a directive, a clause of another predicate, a syntax error, a policy of
another learner or another domain, a term a learner refuses — raises

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
    forall(policy_once(Template), once_only(File, Template, Terms)),
    pairs_values_(Terms, Values),
    catch(learner_restore_(Learner, KB, Values), error(Formal, _),
          restore_error(File, Terms, Formal)).

%!  policy_once(?Template) is nondet.
%
%   A policy file holds at most one term that Template subsumes (a learner's whole tree,
%   such as tg_tree/1): a second is refused, naming its line, rather than one of the two
%   being silently restored. Learners add clauses (multifile).

:- multifile policy_once/1.

%   The second term of Terms that Template subsumes, if any, is an error naming its line.
once_only(File, Template, Terms) :-
    (   append(_, [Line1-T1|Rest], Terms),
        subsumes_term(Template, T1)
    ->  (   member(Line2-T2, Rest),
            subsumes_term(Template, T2)
        ->  functor(T2, Name, Arity),
            policy_error(File, Line2, "a second ~q (the first is on line ~d): a policy holds \c
                         one", [Name/Arity, Line1])
        ;   true
        )
    ;   true
    ).

%!  policy_refuse(+Term, +Format, +Args) is det.
%
%   A learner's restore hook refuses the policy because of Term, a term read from the
%   policy file or a part of one: the error names the file and the line of the term that
%   holds it, with the message Format/Args (~q shows a variable of Args as _ or A, B ...).
%
%   @error relrl_policy_refused(Term, Message), always.

policy_refuse(Term, Format, Args) :-
    copy_term(Args, Shown),                      % variables shown as _, A, B ...
    numbervars(Shown, 0, _, [singletons(true)]),
    format(string(Message), Format, Shown),
    throw(error(relrl_policy_refused(Term, Message), _)).

%!  policy_max_number(-Max) is det.
%
%   The largest magnitude a learned value (a Q-value, a fitness, a count) of a policy may
%   have: far above any value learning reaches, and far enough below the largest float that
%   no update can overflow.

policy_max_number(1.0e15).

%!  policy_number(+Term, +What, +Number) is det.
%
%   Number, the value What of policy term Term, is an integer or a finite float of
%   magnitude at most policy_max_number/1.
%
%   @error relrl_policy_refused(Term, Message) otherwise (see policy_refuse/3).

policy_number(Term, What, X) :-
    (   in_range(X)
    ->  true
    ;   number(X)
    ->  policy_max_number(Max),
        shown(X, Shown),
        policy_refuse(Term, "~w ~w is out of range: a policy's values are finite numbers of \c
                             magnitude at most ~g", [What, Shown, Max])
    ;   policy_refuse(Term, "~w ~q is not a number", [What, X])
    ).

%   A number as text, an integer of more than 20 digits by its length.
shown(X, Shown) :-
    (   integer(X),
        format(string(Digits), "~d", [X]),
        string_length(Digits, L),
        L > 20
    ->  format(string(Shown), "(an integer of ~d digits)", [L])
    ;   format(string(Shown), "~q", [X])
    ).

in_range(X) :-
    policy_max_number(Max),
    (   integer(X)
    ->  abs(X) =< integer(Max)
    ;   finite_float(X),
        abs(X) =< Max
    ).

finite_float(X) :-
    float(X),
    float_class(X, Class),
    Class \== nan,
    Class \== infinite.

learner_restore_(Learner, KB, Values) :-
    (   relrl_engine:learner_restore(Learner, KB, Values)
    ->  true
    ;   existence_error(policy_restore, Learner)
    ).

%   A policy is read whole before it is checked: a file larger than 1/32 of Prolog's stack
%   limit (16 MB with relrl's 512 MB) is refused before reading, so that no policy can
%   exhaust the stack (a term takes up to about 12 times its text).
open_policy(File, S) :-
    (   exists_file(File)
    ->  true
    ;   exists_directory(File)
    ->  policy_error(File, 0, "a folder, not a policy file", [])
    ;   access_file(File, exist)
    ->  policy_error(File, 0, "not a regular file (a device, a pipe or a socket), not a \c
                     policy file", [])
    ;   policy_error(File, 0, "no such policy file", [])
    ),
    size_file(File, Size),
    current_prolog_flag(stack_limit, Stack),
    Max is Stack // 32,
    (   Size =< Max
    ->  open(File, read, S, [encoding(utf8)])
    ;   policy_error(File, 0, "~D bytes, larger than a policy relrl reads (at most ~D bytes, \c
                     1/32 of Prolog's stack limit)", [Size, Max])
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

%   The file's Info must hold every Key(Value) of the loaded domain's
%   (relrl_engine:engine_policy_info/2: features and responses, or what the learner's
%   policy is tied to), each the same up to variable names.
check_info(KB, File, Line, Info) :-
    engine_policy_info(KB, Ours),
    maplist(check_info_item(File, Line, Info), Ours).

check_info_item(File, Line, Info, Item) :-
    Item =.. [Key, Value],
    Theirs0 =.. [Key, Theirs],
    (   memberchk(Theirs0, Info)
    ->  true
    ;   policy_error(File, Line, "relrl_policy/2 does not list the domain's ~w (a policy \c
                     of an older relrl?)", [Key])
    ),
    (   Theirs =@= Value
    ->  true
    ;   is_list(Theirs), is_list(Value)
    ->  first_difference(Theirs, Value, T1, O1),
        policy_error(File, Line, "learned for another domain: its ~w differ from the \c
                     loaded domain's (~q in the policy, ~q in the domain)", [Key, T1, O1])
    ;   policy_error(File, Line, "learned for another domain: its ~w differ from the \c
                     loaded domain's", [Key])
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
    check_numbers(File, Line, T),
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

%   Every number of a policy term is an integer or a finite float: no learner writes
%   infinities, NaN or rationals (1r3), and none reads them.
check_numbers(File, Line, T) :-
    (   bad_number(T, X)
    ->  (   float(X)
        ->  policy_error(File, Line, "~q is not a finite number (a policy holds finite \c
                                     numbers only)", [X])
        ;   policy_error(File, Line, "~q is a rational number (a policy holds integers and \c
                                     floats only)", [X])
        )
    ;   true
    ).

%   X is the first number of T that is neither an integer nor a finite float. A walk over
%   the arguments, the last one a tail call (a list of millions is walked in constant
%   stack).
bad_number(T, X) :-
    (   number(T)
    ->  \+ integer(T),
        \+ finite_float(T),
        X = T
    ;   compound(T)
    ->  compound_name_arity(T, _, N),
        bad_number_arg(1, N, T, X)
    ).

bad_number_arg(I, N, T, X) :-
    arg(I, T, A),
    (   I =:= N
    ->  bad_number(A, X)
    ;   bad_number(A, X)
    ->  true
    ;   I1 is I + 1,
        bad_number_arg(I1, N, T, X)
    ).

%   A learner refused the policy: name the line of the term it refused (for an ISO error,
%   of the first term holding the culprit; line 0 when none does).
restore_error(File, Terms, Formal) :-
    (   Formal = relrl_policy_refused(Culprit, Message)
    ->  culprit_line(Terms, Culprit, Line),
        policy_error(File, Line, "~w", [Message])
    ;   memberchk(Formal, [type_error(_, _), domain_error(_, _), existence_error(_, _),
                           instantiation_error])
    ->  (   memberchk(Formal, [type_error(_, Culprit), domain_error(_, Culprit)])
        ->  culprit_line(Terms, Culprit, Line)
        ;   Line = 0
        ),
        message_text(error(Formal, _), Text),
        policy_error(File, Line, "bad policy: ~s", [Text])
    ;   throw(error(Formal, _))
    ).

culprit_line(Terms, Culprit, Line) :-
    (   member(Line0-T, Terms),
        T =@= Culprit
    ->  Line = Line0
    ;   member(Line0-T, Terms),
        sub_term(S, T),
        S =@= Culprit
    ->  Line = Line0
    ;   Line = 0
    ).

policy_error(File, Line, Format, Args) :-
    format(string(Message), Format, Args),
    throw(error(relrl_policy_error(File, Line, Message), _)).
