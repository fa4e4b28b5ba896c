#pragma once
//! \file
//! exp, log and pow for the real-time core: header-only, no dependencies, no allocation,
//! noexcept, and accurate (not a fast-math approximation): exp 0.51 ulp, log < 1 ulp, pow
//! 0.51 ulp for moderate exponents; see the bounds at the functions below and
//! tests/cpp/test_fast_math.cpp, which measures them against long double.
//!
//! Why: the CoR estimator needs two pows, one log and one exp per sample. glibc's versions are
//! calls through the PLT (and an ifunc) that the compiler cannot inline; these inline into the
//! caller and share one exp and one log kernel. glibc 2.36 on x86-64 dispatches to FMA code, so
//! per call these are not much faster (measured: exp 3.1 vs 5.9 ns throughput, log and pow
//! equal, latency 5-20 % longer without FMA); the gain in the CoR estimator is ~1-2 %.
//!
//! Method (double arithmetic with round to nearest; no FMA needed, std::fma is used only where
//! the target has it in hardware, __FMA__, since otherwise it is a slow library call):
//!
//! exp(x_hi + x_lo): x = (128 e + j) ln2/128 + r, |r| <= ln2/256 (Cody-Waite: ln2/128 split into
//!   kExpLn2HiN, 35 significant bits so that n hi is exact for |n| < 2^18, and kExpLn2LoN; the
//!   subtraction x_hi - n hi is exact by Sterbenz). e^x = 2^e 2^(j/128) e^r. kExpTable holds
//!   2^(j/128) = T (1 + tail) with T stored as its bits minus j << 45, so that adding n << 45
//!   gives the bits of 2^e T directly. e^r - 1 = p by its Taylor polynomial of degree 5
//!   (truncation |r|^6/6! < 2^-60). Result s + s (tail + p) with s = 2^e T: one final rounding
//!   after errors below 2^-58 relative.
//!
//! log(x) as hi + lo: x = 2^k z with z in [0.6875, 1.375) by bit arithmetic (subnormals are
//!   normalised first); the top 7 bits of the mantissa offset select one of 128 intervals.
//!   kLogTable holds per interval its midpoint c (<= 10 significant bits; exactly 1 on the two
//!   intervals next to 1, so that log keeps its relative accuracy near x = 1), 1/c rounded, and
//!   log c as logc_hi (a multiple of 2^-42) + logc_lo. z - c is exact (Sterbenz) and
//!   r = (z - c) (1/c) has a relative error <= 2^-52 (exact where c = 1), |r| <= 2^-7.
//!   log x = k ln2 + log c + log1p(r): k ln2_hi + logc_hi is exact (multiples of 2^-42 below
//!   2^10), adding r is an exact two-sum, log1p(r) - r is its Taylor series to r^9 (truncation
//!   |r|^10/10 < 2^-73), k ln2_lo + logc_lo a small correction. Error of hi + lo: <= 2^-52 |r|
//!   from r (<= 2^-60 absolute, none where c = 1) plus about 2^-53 r^2 from the series, i.e.
//!   2^-60 absolute, and 2^-60 relative near x = 1.
//!
//! pow(x, y) = exp(y log x): y (hi + lo) as a double-double from an exact product of the 26-bit
//!   heads of y and hi (bit masks) plus the three small cross terms, then exp of the
//!   double-double. The argument error is about 2^-60 max(|y|, |y log x|).
//!
//! Coefficients: 1/n (log1p) and 1/n! (exp) rounded to double. The tables and split constants
//! were generated with mpmath at 200 bits: 2^(j/128), -log(invc) and ln2 rounded to nearest with
//! the hi parts rounded to the grids stated above; invc = 2 / (z_0 + z_1) of the interval
//! [z_0, z_1) rounded to 21 significant bits. The tests check every table entry against long
//! double.
//!
//! Requirements: IEEE double with round to nearest, no -ffast-math (checked below), no x87
//! excess precision (FLT_EVAL_METHOD == 0, checked below).

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#if defined(__FAST_MATH__)
#error "lugrip/detail/fast_math.hpp relies on exact IEEE rounding: do not compile with -ffast-math"
#endif
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD != 0
#error "lugrip/detail/fast_math.hpp needs FLT_EVAL_METHOD == 0 (SSE2 doubles, no x87 excess precision)"
#endif

#if defined(__GNUC__)
#define LUGRIP_FM_UNLIKELY(c) __builtin_expect(!!(c), 0)
#define LUGRIP_FM_COLD __attribute__((noinline, cold))
#else
#define LUGRIP_FM_UNLIKELY(c) (c)
#define LUGRIP_FM_COLD
#endif

namespace lugrip {
namespace detail {
namespace fm {

inline std::uint64_t as_u64(double x) noexcept {
  std::uint64_t u;
  std::memcpy(&u, &x, sizeof u);
  return u;
}
inline double as_f64(std::uint64_t u) noexcept {
  double x;
  std::memcpy(&x, &u, sizeof x);
  return x;
}

struct ExpEntry {
  double tail;          // 2^(j/128) = T (1 + tail)
  std::uint64_t sbits;  // bits of T minus (j << 45)
};
struct LogEntry {
  double c, invc, logc_hi, logc_lo;  // interval midpoint, 1/c rounded, log c = logc_hi + logc_lo
};

inline constexpr double kShift = 6755399441055744.0;  // 1.5 * 2^52: x + kShift - kShift rounds x to an integer
inline constexpr double kExpInvLn2N = 184.6649652337873;             // 128 / ln2
inline constexpr double kExpLn2HiN = 0.0054152123482253955;          // ln2/128, multiple of 2^-42 (35 bits)
inline constexpr double kExpLn2LoN = -1.0082281460997769e-13;        // ln2/128 - kExpLn2HiN
inline constexpr double kLn2Hi = 0.6931471805598903;                 // ln2, multiple of 2^-42
inline constexpr double kLn2Lo = 5.497923018708371e-14;              // ln2 - kLn2Hi
inline constexpr std::uint64_t kLogOff = 0x3fe6000000000000ULL;      // bits of 0.6875
inline constexpr std::uint64_t kMinNormal = 0x0010000000000000ULL;   // bits of DBL_MIN
inline constexpr std::uint64_t kNormalSpan = 0x7fe0000000000000ULL;  // bits(inf) - bits(DBL_MIN)

inline constexpr ExpEntry kExpTable[128] = {
    {0.0, 0x3ff0000000000000ULL},
    {9.447885451727066e-17, 0x3feff63da9fb3335ULL},
    {-1.507066976926039e-17, 0x3fefec9a3e778061ULL},
    {-5.679155082825012e-17, 0x3fefe315e86e7f85ULL},
    {4.9997448722726326e-17, 0x3fefd9b0d3158574ULL},
    {-4.823683599994895e-17, 0x3fefd06b29ddf6deULL},
    {7.357846871247418e-18, 0x3fefc74518759bc8ULL},
    {5.773230223741951e-17, 0x3fefbe3ecac6f383ULL},
    {8.189317638195515e-17, 0x3fefb5586cf9890fULL},
    {5.326891139980878e-17, 0x3fefac922b7247f7ULL},
    {1.6665881442326747e-18, 0x3fefa3ec32d3d1a2ULL},
    {-1.128113245461828e-17, 0x3fef9b66affed31bULL},
    {-7.402825309426177e-17, 0x3fef9301d0125b51ULL},
    {-3.578659767309563e-18, 0x3fef8abdc06c31ccULL},
    {-6.170654745608695e-17, 0x3fef829aaea92de0ULL},
    {2.919139999949279e-17, 0x3fef7a98c8a58e51ULL},
    {-2.7939114859515733e-17, 0x3fef72b83c7d517bULL},
    {-5.399285355184285e-17, 0x3fef6af9388c8deaULL},
    {4.776959425256223e-17, 0x3fef635beb6fcb75ULL},
    {-7.927701432338473e-17, 0x3fef5be084045cd4ULL},
    {9.341710609905046e-17, 0x3fef54873168b9aaULL},
    {-5.534520675707472e-17, 0x3fef4d5022fcd91dULL},
    {4.585670326662351e-17, 0x3fef463b88628cd6ULL},
    {2.8582430411116143e-17, 0x3fef3f49917ddc96ULL},
    {7.826573258636076e-17, 0x3fef387a6e756238ULL},
    {4.053626906769216e-17, 0x3fef31ce4fb2a63fULL},
    {2.823784425951061e-17, 0x3fef2b4565e27cddULL},
    {-7.882802262487991e-17, 0x3fef24dfe1f56381ULL},
    {3.2904726646008416e-17, 0x3fef1e9df51fdee1ULL},
    {-1.5792094703347882e-18, 0x3fef187fd0dad990ULL},
    {4.721368121170128e-17, 0x3fef1285a6e4030bULL},
    {1.3045277096919659e-17, 0x3fef0cafa93e2f56ULL},
    {3.3484623336251524e-17, 0x3fef06fe0a31b715ULL},
    {3.8611199774925664e-17, 0x3fef0170fc4cd831ULL},
    {5.527550048505249e-17, 0x3feefc08b26416ffULL},
    {-3.927184172445234e-17, 0x3feef6c55f929ff1ULL},
    {-6.346552106729483e-17, 0x3feef1a7373aa9cbULL},
    {-8.684417614865944e-17, 0x3feeecae6d05d866ULL},
    {-1.5456342819397733e-17, 0x3feee7db34e59ff7ULL},
    {-8.70763476495455e-17, 0x3feee32dc313a8e5ULL},
    {3.750854201303127e-17, 0x3feedea64c123422ULL},
    {-6.616854503526488e-17, 0x3feeda4504ac801cULL},
    {-5.346099009198751e-18, 0x3feed60a21f72e2aULL},
    {-2.443726321015018e-17, 0x3feed1f5d950a897ULL},
    {2.1023049675215714e-18, 0x3feece086061892dULL},
    {7.771067937501065e-17, 0x3feeca41ed1d0057ULL},
    {1.3357510088834541e-17, 0x3feec6a2b5c13cd0ULL},
    {6.938291696959204e-17, 0x3feec32af0d7d3deULL},
    {1.9572585293112036e-17, 0x3feebfdad5362a27ULL},
    {6.632256961675804e-17, 0x3feebcb299fddd0dULL},
    {-5.478069123926778e-17, 0x3feeb9b2769d2ca7ULL},
    {-4.140839310392624e-17, 0x3feeb6daa2cf6642ULL},
    {-2.1571477251208752e-17, 0x3feeb42b569d4f82ULL},
    {-3.8287766552120535e-17, 0x3feeb1a4ca5d920fULL},
    {6.663804589232195e-17, 0x3feeaf4736b527daULL},
    {2.3936187400285282e-17, 0x3feead12d497c7fdULL},
    {5.68648095791174e-17, 0x3feeab07dd485429ULL},
    {1.1264523354521684e-18, 0x3feea9268a5946b7ULL},
    {7.007875046906994e-17, 0x3feea76f15ad2148ULL},
    {-5.0119214278381254e-17, 0x3feea5e1b976dc09ULL},
    {-4.8923067513522756e-17, 0x3feea47eb03a5585ULL},
    {-3.5260089953269434e-17, 0x3feea34634ccc320ULL},
    {-6.872303720902018e-17, 0x3feea23882552225ULL},
    {5.001446664133532e-18, 0x3feea155d44ca973ULL},
    {-6.835808657661922e-17, 0x3feea09e667f3bcdULL},
    {-1.1307344092910212e-17, 0x3feea012750bdabfULL},
    {-8.416011634717156e-18, 0x3fee9fb23c651a2fULL},
    {-2.9247977035436566e-17, 0x3fee9f7df9519484ULL},
    {-2.092304381843353e-17, 0x3fee9f75e8ec5f74ULL},
    {-3.9778645875427124e-17, 0x3fee9f9a48a58174ULL},
    {-3.833464968654295e-17, 0x3fee9feb564267c9ULL},
    {5.763611164480894e-17, 0x3feea0694fde5d3fULL},
    {-2.3591094770850053e-17, 0x3feea11473eb0187ULL},
    {7.260074661098575e-17, 0x3feea1ed0130c132ULL},
    {9.50689710108796e-18, 0x3feea2f336cf4e62ULL},
    {-4.272956133839906e-17, 0x3feea427543e1a12ULL},
    {-6.735219232374683e-17, 0x3feea589994cce13ULL},
    {-2.8396044410430936e-17, 0x3feea71a4623c7adULL},
    {-7.226635472101257e-17, 0x3feea8d99b4492edULL},
    {5.786121003395918e-17, 0x3feeaac7d98a6699ULL},
    {5.1548301170786783e-17, 0x3feeace5422aa0dbULL},
    {-9.416257568878152e-18, 0x3feeaf3216b5448cULL},
    {2.4253985766689806e-17, 0x3feeb1ae99157736ULL},
    {-6.604314051707707e-17, 0x3feeb45b0b91ffc6ULL},
    {-6.432131775424189e-18, 0x3feeb737b0cdc5e5ULL},
    {-1.2204007601863921e-17, 0x3feeba44cbc8520fULL},
    {-6.336161863401293e-17, 0x3feebd829fde4e50ULL},
    {-3.7800879246373815e-17, 0x3feec0f170ca07baULL},
    {1.5341410053603723e-17, 0x3feec49182a3f090ULL},
    {1.2932855580427452e-17, 0x3feec86319e32323ULL},
    {-4.123367330661149e-17, 0x3feecc667b5de565ULL},
    {4.703083974463456e-17, 0x3feed09bec4a2d33ULL},
    {-6.152602891550265e-17, 0x3feed503b23e255dULL},
    {5.827849326195279e-17, 0x3feed99e1330b358ULL},
    {3.540948262646183e-17, 0x3feede6b5579fdbfULL},
    {-3.2741571320938764e-17, 0x3feee36bbfd3f37aULL},
    {4.875160526227062e-17, 0x3feee89f995ad3adULL},
    {-5.718569790077838e-17, 0x3feeee07298db666ULL},
    {-4.719539664590972e-18, 0x3feef3a2b84f15fbULL},
    {-5.773451958805706e-17, 0x3feef9728de5593aULL},
    {-1.0772487078934056e-17, 0x3feeff76f2fb5e47ULL},
    {-6.221808618533911e-17, 0x3fef05b030a1064aULL},
    {1.821405440362259e-17, 0x3fef0c1e904bc1d2ULL},
    {-6.155536546227639e-17, 0x3fef12c25bd71e09ULL},
    {1.685487290628973e-17, 0x3fef199bdd85529cULL},
    {5.3581249177694816e-17, 0x3fef20ab5fffd07aULL},
    {3.621615935336894e-17, 0x3fef27f12e57d14bULL},
    {8.588379527574144e-18, 0x3fef2f6d9406e7b5ULL},
    {1.01562190116415e-17, 0x3fef3720dcef9069ULL},
    {-2.869134889187244e-17, 0x3fef3f0b555dc3faULL},
    {-5.495118966122005e-17, 0x3fef472d4a07897cULL},
    {-5.56965572431627e-17, 0x3fef4f87080d89f2ULL},
    {1.790126907604513e-17, 0x3fef5818dcfba487ULL},
    {-3.2211766346200164e-17, 0x3fef60e316c98398ULL},
    {5.265370768556274e-17, 0x3fef69e603db3285ULL},
    {3.5089866402403033e-17, 0x3fef7321f301b460ULL},
    {-3.266924100901318e-17, 0x3fef7c97337b9b5fULL},
    {-4.3657593008079375e-17, 0x3fef864614f5a129ULL},
    {1.7963932659833022e-17, 0x3fef902ee78b3ff6ULL},
    {3.4300925275214166e-17, 0x3fef9a51fbc74c83ULL},
    {-5.545065618639427e-17, 0x3fefa4afa2a490daULL},
    {-5.149009745457733e-17, 0x3fefaf482d8e67f1ULL},
    {5.336805878514151e-17, 0x3fefba1bee615a27ULL},
    {3.498978661192973e-17, 0x3fefc52b376bba97ULL},
    {4.5784915277060095e-17, 0x3fefd0765b6e4540ULL},
    {-5.241934575393899e-17, 0x3fefdbfdad9cbe14ULL},
    {2.0414278897578303e-17, 0x3fefe7c1819e90d8ULL},
    {4.124842848606488e-18, 0x3feff3c22b8f71f1ULL},
};

inline constexpr LogEntry kLogTable[128] = {
    {0.689453125, 1.4504249291784703, -0.3718565681062955, 8.45090175564329e-14},
    {0.693359375, 1.4422535211267606, -0.3662068355640713, -2.0690830060414247e-14},
    {0.697265625, 1.4341736694677871, -0.36058884325984764, -2.1072368850361424e-14},
    {0.701171875, 1.426183844011142, -0.35500223655117225, -5.666618030989675e-14},
    {0.705078125, 1.4182825484764543, -0.3494466667066263, -5.90346888093064e-16},
    {0.708984375, 1.4104683195592287, -0.3439217907746297, -2.730651892134709e-14},
    {0.712890625, 1.4027397260273973, -0.33842727145702156, 5.280156204729064e-15},
    {0.716796875, 1.3950953678474114, -0.33296277698491394, -2.3569101751290204e-14},
    {0.720703125, 1.3875338753387534, -0.3275279809990934, 1.1281735060685524e-13},
    {0.724609375, 1.3800539083557952, -0.3221225624320141, -5.855316792709415e-14},
    {0.728515625, 1.3726541554959786, -0.3167462053957024, 1.0174753377507561e-14},
    {0.732421875, 1.3653333333333333, -0.3113985990692072, 1.1022412161041444e-13},
    {0.736328125, 1.3580901856763925, -0.3060794375915066, 9.55418156600115e-15},
    {0.740234375, 1.3509234828496042, -0.30078841995714356, 6.212323048084214e-14},
    {0.744140625, 1.3438320209973753, -0.29552524991277096, -3.586053092023274e-14},
    {0.748046875, 1.3368146214099217, -0.290289635858926, 6.418144637660116e-14},
    {0.751953125, 1.3298701298701299, -0.2850812907518048, 8.12113117496254e-14},
    {0.755859375, 1.322997416020672, -0.2798999320098119, 8.591298393628546e-14},
    {0.759765625, 1.3161953727506426, -0.27474528142101917, -4.2320076202145394e-14},
    {0.763671875, 1.3094629156010231, -0.26961706505403527, -1.0674835088128526e-13},
    {0.767578125, 1.3027989821882953, -0.2645150131702394, -7.150023153018402e-15},
    {0.771484375, 1.2962025316455696, -0.2594388601382889, -9.704226792067357e-14},
    {0.775390625, 1.2896725440806045, -0.25438834435226454, -5.28323330087437e-14},
    {0.779296875, 1.2832080200501252, -0.2493632081495889, -5.5428558531117086e-14},
    {0.783203125, 1.2768079800498753, -0.24436319773303694, 9.834201296269778e-14},
    {0.787109375, 1.2704714640198511, -0.23938806309274696, -7.784172549574863e-14},
    {0.791015625, 1.2641975308641975, -0.23443755793300625, 3.76018844589075e-14},
    {0.794921875, 1.257985257985258, -0.22951143959699039, 7.75890005756947e-14},
    {0.798828125, 1.2518337408312958, -0.22460946899673218, 2.6136541452968644e-14},
    {0.802734375, 1.245742092457421, -0.2197314105433179, 4.472851385991314e-14},
    {0.806640625, 1.2397094430992737, -0.21487703207844788, -2.714636557077735e-14},
    {0.810546875, 1.2337349397590363, -0.21004610480872543, -8.405546663347035e-14},
    {0.814453125, 1.2278177458033572, -0.20523840324062803, -7.830497219227196e-14},
    {0.818359375, 1.2219570405727924, -0.20045370511729743, -7.262215167738776e-14},
    {0.822265625, 1.2161520190023754, -0.19569179135714876, 2.239166785505485e-14},
    {0.826171875, 1.210401891252955, -0.19095244599316175, -6.806942496762734e-14},
    {0.830078125, 1.204705882352941, -0.18623545611512782, 3.68623071742394e-14},
    {0.833984375, 1.199063231850117, -0.18154061181098768, 1.0445339530284443e-13},
    {0.837890625, 1.1934731934731935, -0.17686770611157954, 8.872356517315185e-14},
    {0.841796875, 1.1879350348027842, -0.172216534935842, 8.199467511461324e-14},
    {0.845703125, 1.1824480369515011, -0.16758689703692653, -9.140819889491412e-14},
    {0.849609375, 1.1770114942528735, -0.16297859395081105, -1.2645632984431417e-14},
    {0.853515625, 1.17162471395881, -0.1583914299440039, 8.626913488119114e-14},
    {0.857421875, 1.1662870159453302, -0.15382521196443122, 9.478404105196118e-14},
    {0.861328125, 1.1609977324263039, -0.14927974959255152, -1.1026677017414112e-13},
    {0.865234375, 1.1557562076749435, -0.14475485499428942, -8.272973285564614e-14},
    {0.869140625, 1.150561797752809, -0.14025034287328708, 1.9509765515283165e-14},
    {0.873046875, 1.145413870246085, -0.1357660304258843, -5.4642560554597724e-14},
    {0.876953125, 1.1403118040089086, -0.13130173729723538, -1.811460150533731e-14},
    {0.880859375, 1.1352549889135255, -0.1268572855367438, -8.563445867256504e-14},
    {0.884765625, 1.130242825607064, -0.12243249955645297, -2.0797337102277177e-14},
    {0.888671875, 1.1252747252747253, -0.11802720608852724, -3.013227959910772e-14},
    {0.892578125, 1.1203501094091903, -0.1136412341452342, -6.889214192008475e-14},
    {0.896484375, 1.1154684095860568, -0.10927441497892687, -3.575992997726754e-14},
    {0.900390625, 1.1106290672451193, -0.10492658204293548, 7.621258431924948e-14},
    {0.904296875, 1.1058315334773219, -0.10059757095336863, 9.49206327250953e-14},
    {0.908203125, 1.1010752688172043, -0.09628721945205143, -1.0004154004618119e-13},
    {0.912109375, 1.0963597430406853, -0.09199536737060043, -1.003943822681932e-14},
    {0.916015625, 1.091684434968017, -0.08772185659313436, -9.405807834383626e-14},
    {0.919921875, 1.0870488322717622, -0.08346653102307755, -1.2485591229479935e-14},
    {0.923828125, 1.0824524312896406, -0.07922923654746228, -1.1253882534313481e-13},
    {0.927734375, 1.0778947368421052, -0.07500982100486908, 2.5061174934837362e-15},
    {0.931640625, 1.0733752620545074, -0.07080813415109333, -7.324072905400027e-14},
    {0.935546875, 1.068893528183716, -0.06662402762867714, 8.45908172817448e-14},
    {0.939453125, 1.0644490644490645, -0.06245735493371285, -3.375459077303842e-14},
    {0.943359375, 1.060041407867495, -0.05830797138696653, 3.143092323816711e-14},
    {0.947265625, 1.0556701030927835, -0.05417573410204568, 2.1092591481336484e-14},
    {0.951171875, 1.051334702258727, -0.05006050195697753, 5.953822004049194e-14},
    {0.955078125, 1.047034764826176, -0.04596213556465045, 1.4693284460141064e-14},
    {0.958984375, 1.0427698574338085, -0.041880497245074366, 8.71601984429868e-14},
    {0.962890625, 1.0385395537525355, -0.03781545099673167, -8.600744742060645e-14},
    {0.966796875, 1.0343434343434343, -0.03376686247088401, 6.652375062271929e-14},
    {0.970703125, 1.0301810865191148, -0.029734598942923185, 4.4126629622863087e-14},
    {0.974609375, 1.0260521042084167, -0.02571852928804219, 5.307171319656295e-14},
    {0.978515625, 1.0219560878243512, -0.021718523954632474, -1.0512339808596024e-14},
    {0.982421875, 1.0178926441351888, -0.017734454939727584, -4.0994203403301545e-14},
    {0.986328125, 1.0138613861386139, -0.013766195764219447, 7.148730327496492e-14},
    {0.990234375, 1.009861932938856, -0.009813621448302001, -2.262002617558127e-14},
    {0.994140625, 1.005893909626719, -0.00587660848896121, -2.3831678683970623e-14},
    {1.0, 1.0, 0.0, 0.0},
    {1.0, 1.0, 0.0, 0.0},
    {1.01171875, 0.9884169884169884, 0.011650617220084314, -1.0903974971735932e-13},
    {1.01953125, 0.9808429118773946, 0.019342962843211353, -8.041853850522586e-14},
    {1.02734375, 0.973384030418251, 0.026976587698300136, -9.806050516843177e-14},
    {1.03515625, 0.9660377358490566, 0.034552381506728125, -6.839139742328777e-14},
    {1.04296875, 0.9588014981273408, 0.04207121392073532, -4.826314000551128e-14},
    {1.05078125, 0.9516728624535316, 0.04953393512232651, -4.9880309107981426e-14},
    {1.05859375, 0.9446494464944649, 0.056941376400118315, 2.0109399435564958e-14},
    {1.06640625, 0.9377289377289377, 0.06429435070549516, -9.790518511990216e-14},
    {1.07421875, 0.9309090909090909, 0.07159365318693744, 7.137308225343178e-14},
    {1.08203125, 0.924187725631769, 0.07884006170775137, 2.465018906176612e-14},
    {1.08984375, 0.9175627240143369, 0.0860343373417436, 5.955922987625643e-14},
    {1.09765625, 0.9110320284697508, 0.0931772248541165, 6.678708517162898e-14},
    {1.10546875, 0.9045936395759717, 0.10026945316371894, -4.378637617078398e-14},
    {1.11328125, 0.8982456140350877, 0.10731173578915332, -6.526678802731071e-14},
    {1.12109375, 0.89198606271777, 0.11430477128010352, -4.488953352238699e-14},
    {1.12890625, 0.8858131487889274, 0.12124924363297396, -1.0427241278273008e-13},
    {1.13671875, 0.8797250859106529, 0.12814582269197672, -4.668031403945796e-14},
    {1.14453125, 0.8737201365187713, 0.13499516453748583, 1.8996158041578768e-14},
    {1.15234375, 0.8677966101694915, 0.14179791186029433, -3.698459506697097e-14},
    {1.16015625, 0.8619528619528619, 0.1485546943231384, -1.24915489807516e-15},
    {1.16796875, 0.8561872909698997, 0.15526612891108016, 4.3792508292406054e-14},
    {1.17578125, 0.8504983388704319, 0.16193282026938505, -7.179390019295677e-14},
    {1.18359375, 0.8448844884488449, 0.16855536102980295, 3.714397754170472e-15},
    {1.19140625, 0.839344262295082, 0.17513433212775453, 9.461516580665081e-14},
    {1.19921875, 0.8338762214983714, 0.18167030310769405, -5.937506333384701e-14},
    {1.20703125, 0.8284789644012945, 0.18816383241824042, -5.743078393200756e-14},
    {1.21484375, 0.8231511254019293, 0.1946154676995775, 9.41653814571825e-14},
    {1.22265625, 0.8178913738019169, 0.20102574606062262, -3.188184937543774e-14},
    {1.23046875, 0.8126984126984127, 0.20739519434596332, 1.0726867577289733e-13},
    {1.23828125, 0.807570977917981, 0.21372432939779173, -7.359580186440514e-14},
    {1.24609375, 0.8025078369905956, 0.2200136583053336, -5.149667234141408e-14},
    {1.25390625, 0.7975077881619937, 0.22626367865041175, 4.1641267302872263e-14},
    {1.26171875, 0.7925696594427245, 0.23247487874300532, 8.874507297974632e-14},
    {1.26953125, 0.7876923076923077, 0.23864773785021498, -3.997050909530134e-14},
    {1.27734375, 0.7828746177370031, 0.24478272641772492, -3.399981108361833e-14},
    {1.28515625, 0.7781155015197568, 0.2508803062858078, 1.5973663463624904e-15},
    {1.29296875, 0.7734138972809668, 0.2569409308975992, -9.874803015966392e-14},
    {1.30078125, 0.7687687687687688, 0.2629650455007777, 1.0364636459896663e-13},
    {1.30859375, 0.764179104477612, 0.26895308734560786, -1.0389630784002988e-13},
    {1.31640625, 0.7596439169139466, 0.27490548587275043, 4.8816703646769986e-14},
    {1.32421875, 0.7551622418879056, 0.2808226629008459, 4.188609137863701e-14},
    {1.33203125, 0.750733137829912, 0.28670503280386583, 8.848109604006821e-14},
    {1.33984375, 0.7463556851311953, 0.29255300268641804, -4.0599978860151284e-14},
    {1.34765625, 0.7420289855072464, 0.2983669725517757, 2.159269374197349e-14},
    {1.35546875, 0.7377521613832853, 0.30414733546740536, -1.0863828679707913e-13},
    {1.36328125, 0.7335243553008596, 0.30989447772276435, 1.0033796982039214e-13},
    {1.37109375, 0.7293447293447294, 0.3156087789864159, -1.1259274624680829e-13},
};

// e^(xh + xl) = 2^e T (1 + tail + p): the parts for |xh + xl| <= 745.2.
struct ExpParts {
  std::int64_t n;  // 128 e + j
  double tail_p;   // tail + p
};
// kLo = false: xl is ignored (treated as 0; spares the additions of a zero on the critical path).
template <bool kLo>
inline ExpParts exp_parts(double xh, double xl) noexcept {
  const double kd_shifted = (kLo ? xh + xl : xh) * kExpInvLn2N + kShift;
  // n = round(128 x / ln2), read from the low mantissa bits (two's complement difference)
  const auto n = static_cast<std::int64_t>(as_u64(kd_shifted) - as_u64(kShift));
  const double kd = kd_shifted - kShift;
  // xh - kd hi is exact where |xl| is below ulp(xh), else its rounding error is below 2^-53 |xl|
  const double r = kLo ? (xh - kd * kExpLn2HiN) + (xl - kd * kExpLn2LoN) : (xh - kd * kExpLn2HiN) - kd * kExpLn2LoN;
  // e^r - 1 = (r + r^2/2) + r^3 (1/6 + r/24 + r^2/120), grouped for a short dependency chain
  const double r2 = r * r;
  const double q = (kExpTable[n & 127].tail + (r + 0.5 * r2)) +
                   (r2 * r) * ((1.0 / 6.0 + r * (1.0 / 24.0)) + r2 * (1.0 / 120.0));
  return {n, q};
}

// |xh + xl| > 700 or NaN: overflow, and underflow with subnormal results (below -700, s tail_p of
// exp_dd could be subnormal and lose accuracy, so that range comes here too).
template <bool kLo>
LUGRIP_FM_COLD inline double exp_special(double xh, double xl) noexcept {
  const double x = kLo ? xh + xl : xh;
  if (x != x) return x;                                             // NaN
  if (x > 709.79) return std::numeric_limits<double>::infinity();  // ln(DBL_MAX) = 709.7827
  if (x < -745.2) return 0.0;                                       // ln(2^-1075) = -745.1332
  const ExpParts q = exp_parts<kLo>(xh, xl);
  const std::uint64_t j = static_cast<std::uint64_t>(q.n & 127);
  const std::int64_t e = q.n >> 7;  // arithmetic shift: floor(n / 128)
  const double t = as_f64(kExpTable[j].sbits + (j << 45));  // 2^(j/128) rounded, in [1, 2)
  const double y = t + t * q.tail_p;
  if (e > 0)  // e in [1009, 1024]: 2^e in two steps, overflowing to +inf where the result does
    return (y * as_f64(static_cast<std::uint64_t>(e - 64 + 1023) << 52)) * 0x1p64;
  // e in [-1076, -1010]: work in units of DBL_MIN = 2^-1022 (exact scaling by 2^(e + 1022))
  const double sc = as_f64(static_cast<std::uint64_t>(e + 1022 + 1023) << 52);
  const double s = t * sc, u = t * q.tail_p * sc;
  const double v = s + u;
  if (v >= 1.0) return v * 0x1p-1022;  // normal result
  // Subnormal result: round s + u once to a multiple of 2^-52 (the subnormal spacing in units of
  // DBL_MIN) by adding 1: w = 1 + s + u in [1, 2], then (w - 1) 2^-1022 is exact.
  const double h = 1.0 + s;
  const double l = (1.0 - h) + s;  // exact error of 1 + s
  const double w = h + (l + u);
  return (w - 1.0) * 0x1p-1022;
}

// e^(xh + xl) for a double-double argument (xl need not be below ulp(xh): pow passes the
// unnormalised y log x); kLo = false: e^xh.
template <bool kLo>
inline double exp_dd(double xh, double xl) noexcept {
  if (LUGRIP_FM_UNLIKELY(!(std::fabs(kLo ? xh + xl : xh) <= 700.0))) return exp_special<kLo>(xh, xl);
  const ExpParts q = exp_parts<kLo>(xh, xl);
  // |xh + xl| <= 700: e in [-1011, 1010], the result and s tail_p are normal, the scaling is exact.
  const double s = as_f64(kExpTable[q.n & 127].sbits + (static_cast<std::uint64_t>(q.n) << 45));
  return s + s * q.tail_p;
}

// log of the double with bits ix (positive normal, or a normalised subnormal whose bits carry a
// negative exponent field, see fast_log) as hi + lo, not normalised: |lo| <= 2^-15 + ulp(hi).
inline void log_parts(std::uint64_t ix, double& hi, double& lo) noexcept {
  const std::uint64_t tmp = ix - kLogOff;
  const LogEntry& c = kLogTable[(tmp >> 45) & 127];
  const double kd = static_cast<double>(static_cast<std::int64_t>(tmp) >> 52);  // k (arithmetic shift)
  const double z = as_f64(ix - (tmp & (0xfffULL << 52)));  // z = x 2^-k in [0.6875, 1.375)
  const double r = (z - c.c) * c.invc;  // z - c exact; relative error <= 2^-52 (0 where c = 1)
  const double t1 = kd * kLn2Hi + c.logc_hi;  // exact
  hi = t1 + r;
  const double e = (t1 - hi) + r;  // exact: |t1| >= 0.0058 > |r| unless t1 == 0
  // log1p(r) - r = r^2 (-1/2 + r/3 - r^2/4 + ... + r^7/9)
  const double rr = r * r, r4 = rr * rr;
  const double poly = rr * (((-0.5 + r * (1.0 / 3.0)) + rr * (-0.25 + r * 0.2)) +
                            r4 * ((-1.0 / 6.0 + r * (1.0 / 7.0)) + rr * (-0.125 + r * (1.0 / 9.0))));
  lo = (e + (kd * kLn2Lo + c.logc_lo)) + poly;
}

// The head of x: its 26 leading significant bits (the rest cleared), so that products of two
// heads are exact.
inline double head26(double x) noexcept { return as_f64(as_u64(x) & 0xfffffffff8000000ULL); }

// x^y for x > 0 with bits ix as in log_parts, |y| < 2^64.
inline double pow_core(std::uint64_t ix, double y) noexcept {
  double lh, ll;  // lh is available before the series in ll: the product starts with it
  log_parts(ix, lh, ll);
#if defined(__FMA__)
  const double zh = y * lh;
  const double zl = std::fma(y, lh, -zh) + y * ll;
#else
  // y lh = yh lhh (exact) + yh (lh - lhh) + (y - yh) lh (relative 2^-25, rounded)
  const double yh = head26(y), lhh = head26(lh);
  const double zh = yh * lhh;
  const double zl = (yh * (lh - lhh) + (y - yh) * lh) + y * ll;
#endif
  return exp_dd<true>(zh, zl);
}

// x^y for x >= +0 outside the fast path (x zero, subnormal or +inf, or |y| >= 2^64), y not NaN.
inline double pow_nonneg_special(double x, double y) noexcept {
  constexpr double inf = std::numeric_limits<double>::infinity();
  if (x == 0.0) return y > 0.0 ? 0.0 : inf;
  if (x == inf) return y > 0.0 ? inf : 0.0;
  if (x == 1.0) return 1.0;
  if (!(std::fabs(y) < 0x1p64)) return (x > 1.0) == (y > 0.0) ? inf : 0.0;  // |y log x| > 2^11
  if (x < 0x1p-1022)  // subnormal: normalise (the bits then carry a negative exponent field)
    return pow_core(as_u64(x * 0x1p52) - (52ULL << 52), y);
  return pow_core(as_u64(x), y);
}

// Everything outside the fast path, with the special values of std::pow (C99 Annex F).
LUGRIP_FM_COLD inline double pow_special(double x, double y) noexcept {
  if (y == 0.0) return 1.0;  // for any x, NaN included
  if (x != x) return x + y;  // NaN
  if (x == 1.0) return 1.0;  // for any y, NaN included
  if (y != y) return y + y;
  if (!std::signbit(x)) return pow_nonneg_special(x, y);
  // x negative or -0: |x|^y, negated for odd integer y; NaN for finite x < 0 and non-integer y
  const bool y_integer = std::trunc(y) == y;  // true for +-inf (even)
  if (!y_integer && x != 0.0 && x != -std::numeric_limits<double>::infinity())
    return std::numeric_limits<double>::quiet_NaN();
  const bool odd = y_integer && std::fabs(y) < 0x1p53 && (static_cast<std::int64_t>(y) & 1) != 0;
  const double r = pow_nonneg_special(-x, y);
  return odd ? -r : r;
}

}  // namespace fm

//! e^x within 0.5 + 2^-6 ulp (measured max 0.51 ulp). exp(NaN) = NaN,
//! exp(-inf) = +0, exp(+inf) = +inf, +inf above ln(DBL_MAX), gradual underflow (subnormal
//! results rounded once), +0 below ln(2^-1075).
inline double fast_exp(double x) noexcept { return fm::exp_dd<false>(x, 0.0); }

//! Natural logarithm within 1 ulp: measured max 0.79 ulp in the intervals next to the two around
//! 1 (x in about [0.992, 0.996) and [1.008, 1.016), where the rounding of r is worth up to 1/2
//! ulp of the result), 0.54 ulp over the whole range otherwise. log(+-0) = -inf,
//! log(x < 0) = NaN, log(NaN) = NaN, log(+inf) = +inf, log(1) = +0; subnormal arguments are
//! normalised exactly.
inline double fast_log(double x) noexcept {
  std::uint64_t ix = fm::as_u64(x);
  if (LUGRIP_FM_UNLIKELY(ix - fm::kMinNormal >= fm::kNormalSpan)) {  // not a positive normal finite
    if (x == 0.0) return -std::numeric_limits<double>::infinity();
    if (x != x) return x + x;
    if (x < 0.0) return std::numeric_limits<double>::quiet_NaN();
    if (x == std::numeric_limits<double>::infinity()) return x;
    ix = fm::as_u64(x * 0x1p52) - (52ULL << 52);  // positive subnormal
  }
  double hi, lo;
  fm::log_parts(ix, hi, lo);
  return hi + lo;
}

//! x^y. Fast path for x > 0 (what the core needs: forces and normalised loads to a real
//! exponent): error <= 0.51 + |y|/128 ulp (log x carries an absolute error <= 2^-60), i.e.
//! < 0.6 ulp for |y| <= 10 (measured max 0.51 ulp for x in [1e-6, 1e6], y in [0, 2]) and < 1 ulp
//! for |y| <= 60; for larger |y| with x near 1 (|y log x| up to 745) the error grows to hundreds
//! of ulp: use std::pow there. Everything else (zeros, subnormal x, infinities, NaN, negative x,
//! |y| >= 2^64) goes to a cold path with the special values of std::pow (C99 Annex F), negative x
//! included (NaN for non-integer y, odd integer y keep the sign).
inline double fast_pow_pos(double x, double y) noexcept {
  const std::uint64_t ix = fm::as_u64(x);
  if (LUGRIP_FM_UNLIKELY(ix - fm::kMinNormal >= fm::kNormalSpan || !(std::fabs(y) < 0x1p64)))
    return fm::pow_special(x, y);
  return fm::pow_core(ix, y);
}

}  // namespace detail
}  // namespace lugrip

#undef LUGRIP_FM_UNLIKELY
#undef LUGRIP_FM_COLD
