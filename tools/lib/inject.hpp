// inject.hpp - a known effect added to a real recording (pmfit simulate
// --inject EFFECT --into RUN OUT): the run's observed positions displaced by
// the effect, its noise and everything else unchanged, written as a
// named-column run.  The proof of explain on real data (docs/explain.md,
// "Real recordings with injected effects").
#ifndef PM_INJECT_HPP
#define PM_INJECT_HPP

#include "fitrun.hpp"

#include <string>
#include <vector>

namespace pmhost {

struct Injection {
    std::string effect;     // any pmfit fit --add EFFECT, outlier[:N], higher_order
    double size = 1;        // the effect's parameter (as pmfit simulate --effect)
    bool in_sigma = true;   // size in units of the run's baseline sigma, else arcsec
    double phase_deg = 0;   // periodic effects
    unsigned long long seed = 1; // outliers, higher_order
};

struct InjectReport {
    int order = 1;                  // baseline order the frame and sigma come from
    double sigma_arcsec = 0;        // the run's baseline sigma
    std::vector<double> size_arcsec; // per injection, the parameter used
    std::vector<double> rms_arcsec;  // per injection, RMS displacement per axis on the sky
    std::vector<std::vector<int>> moved; // outliers: the observations moved (indices)
};

// Parse "EFFECT", "EFFECT=SIZE" (arcsec) or "EFFECT:SIZEsigma" /
// "EFFECT:SIZEas" (the colon form needs the unit, since EFFECT has colons of
// its own: ha_periodic:240:2).  Throws std::runtime_error with the reason.
Injection parse_injection(const std::string &spec);

// Displace the observed positions of `run` by the effects (in the frame of
// the run's own baseline fit, order 1, or 0 for runs too small for it).
// Throws std::runtime_error naming the effect or file:line on failure; the
// run is unchanged then.
InjectReport inject(Run &run, const std::vector<Injection> &list);

// Write the run in the named-column format (docs/formats.md) with every
// observation's inputs, through a temporary file.  Throws on failure.
void write_named_run(const Run &run, const std::string &path,
                     const std::vector<std::string> &comments);

} // namespace pmhost

#endif
