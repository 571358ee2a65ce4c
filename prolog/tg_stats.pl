:- module(relrl_tg_stats,
          [ stats_empty/1,        % -Stats
            stats_add/3,          % +Stats0, +Value, -Stats
            stats_mean/2,         % +Stats, -Mean
            stats_sse/2,          % +Stats, -SSE
            split_f/4,            % +Total, +Yes, -F, -Dof
            f_p_value/4,          % +F, +D1, +D2, -P
            f_significant/3,      % +F, +D2, +Level
            incomplete_beta/4     % +X, +A, +B, -I
          ]).
:- use_module(library(error)).

/** <module> Incremental statistics and the F-test of a TG split

A TG leaf keeps, for the TD errors of the examples that reached it (tg.pl) and for each
candidate test, only three numbers: the count, the sum and the sum of squares,
s(N, Sum, SumSq). They are enough for the regression tree's split criterion (Blockeel & De
Raedt's TILDE, Driessens et al.'s TG): a test partitions a leaf's examples into those where
it succeeds (Yes) and fails (No = Total - Yes), and the split is worth making when the two
partitions' means differ by more than chance. The F statistic of the one-way analysis of
variance with two groups is

    F = (SSE_total - SSE_split) / (SSE_split / (N - 2)),      Dof = (1, N - 2)

with SSE the sum of squared deviations from the mean: SSE(s(N, S, SS)) = SS - S^2 / N.
F(1, d) is the square of Student's t with d degrees of freedom, and

    P(F(1, d) > f) = I_{d / (d + f)}(d / 2, 1 / 2)

where I is the regularized incomplete beta function, computed here by its continued
fraction (the modified Lentz method).
*/

%!  stats_empty(-Stats) is det.
%
%   Stats is s(0, 0.0, 0.0): no values yet.

stats_empty(s(0, 0.0, 0.0)).

%!  stats_add(+Stats0, +Value:number, -Stats) is det.
%
%   Stats counts Value too.

stats_add(s(N0, S0, SS0), V, s(N, S, SS)) :-
    N is N0 + 1,
    S is S0 + V,
    SS is SS0 + V * V.

%!  stats_mean(+Stats, -Mean:float) is semidet.
%
%   Mean of the values counted; fails when there are none.

stats_mean(s(N, S, _), Mean) :-
    N > 0,
    Mean is S / N.

%!  stats_sse(+Stats, -SSE:float) is det.
%
%   The sum of squared deviations from the mean (0 for no values; never negative, even
%   when rounding would make it so).

stats_sse(s(N, S, SS), SSE) :-
    (   N > 0
    ->  SSE is max(0.0, SS - S * S / N)
    ;   SSE = 0.0
    ).

%!  split_f(+Total, +Yes, -F:float, -Dof:integer) is semidet.
%
%   F is the F statistic of splitting the values counted in Total into those counted in
%   Yes and the rest; Dof = N - 2 its second degrees of freedom. Fails when a side is empty
%   or Total has fewer than three values. A split that explains all the variance has
%   F = inf (when there was variance to explain) or 0.0 (when there was none). Counts may
%   be weights (a learner that forgets halves them): Dof is then the whole part of N - 2.

split_f(s(N, S, SS), s(N1, S1, SS1), F, Dof) :-
    N1 > 0,
    N2 is N - N1,
    N2 > 0,
    N >= 3,
    Dof is truncate(N) - 2,
    stats_sse(s(N, S, SS), Total),
    S2 is S - S1, SS2 is SS - SS1,
    stats_sse(s(N1, S1, SS1), E1),
    stats_sse(s(N2, S2, SS2), E2),
    Within is E1 + E2,
    Between is max(0.0, Total - Within),
    (   Within =< 1.0e-12 * max(1.0, Total)
    ->  (   Between > 1.0e-12
        ->  F = inf
        ;   F = 0.0
        )
    ;   F is Between / (Within / Dof)
    ).

%!  f_significant(+F, +Dof:integer, +Level:float) is semidet.
%
%   F, with (1, Dof) degrees of freedom, is significant at Level: P(F(1, Dof) > F) < Level.
%   F(1, d) is the square of Student's t, whose tails are heavier than the normal's: when
%   the normal tail P(|Z| > sqrt(F)) = erfc(sqrt(F / 2)) is not below Level, neither is P,
%   and the incomplete beta function is not needed.

f_significant(F, Dof, Level) :-
    (   F == inf
    ->  true
    ;   F > 1.0,
        erfc(sqrt(F / 2)) < Level,          % the normal limit: a lower bound of P
        f_p_value(F, 1, Dof, P),
        P < Level
    ).

%!  f_p_value(+F:number, +D1:integer, +D2:integer, -P:float) is det.
%
%   P is the probability that an F(D1, D2)-distributed variable exceeds F:
%   I_{D2 / (D2 + D1 F)}(D2 / 2, D1 / 2).

f_p_value(F, D1, D2, P) :-
    must_be(positive_integer, D1),
    must_be(positive_integer, D2),
    (   F == inf
    ->  P = 0.0
    ;   F =< 0
    ->  P = 1.0
    ;   X is D2 / (D2 + D1 * F),
        A is D2 / 2, B is D1 / 2,
        incomplete_beta(X, A, B, P)
    ).

%!  incomplete_beta(+X, +A, +B, -I:float) is det.
%
%   I is the regularized incomplete beta function I_X(A, B), for 0 =< X =< 1 and A, B > 0.

incomplete_beta(X, A, B, I) :-
    (   X =< 0
    ->  I = 0.0
    ;   X >= 1
    ->  I = 1.0
    ;   LogFront is lgamma(A + B) - lgamma(A) - lgamma(B) + A * log(X) + B * log(1 - X),
        (   X < (A + 1) / (A + B + 2)
        ->  beta_fraction(X, A, B, CF),
            I is exp(LogFront) * CF / A
        ;   X1 is 1 - X,
            beta_fraction(X1, B, A, CF),
            I is 1 - exp(LogFront) * CF / B
        )
    ).

%   The continued fraction of the incomplete beta function, by the modified Lentz method.
beta_fraction(X, A, B, CF) :-
    Tiny = 1.0e-300,
    D0 is 1 - (A + B) * X / (A + 1),
    nonzero(D0, Tiny, D0n),
    D1 is 1 / D0n,
    lentz(1, X, A, B, Tiny, 1.0, D1, D1, CF).

nonzero(V, Tiny, W) :-
    (   abs(V) < Tiny
    ->  W = Tiny
    ;   W = V
    ).

lentz(M, X, A, B, Tiny, C0, D0, H0, H) :-
    M2 is 2 * M,
    Even is M * (B - M) * X / ((A + M2 - 1) * (A + M2)),
    step(Even, Tiny, C0, D0, H0, C1, D1, H1),
    Odd is -(A + M) * (A + B + M) * X / ((A + M2) * (A + M2 + 1)),
    step(Odd, Tiny, C1, D1, H1, C2, D2, H2),
    Delta is abs(H2 / H1 - 1),
    (   ( Delta < 1.0e-12 ; M >= 300 )
    ->  H = H2
    ;   M1 is M + 1,
        lentz(M1, X, A, B, Tiny, C2, D2, H2, H)
    ).

step(Coef, Tiny, C0, D0, H0, C, D, H) :-
    Dx is 1 + Coef * D0,
    nonzero(Dx, Tiny, Dn),
    D is 1 / Dn,
    Cx is 1 + Coef / C0,
    nonzero(Cx, Tiny, C),
    H is H0 * D * C.
