#ifndef BEAMSIM_VERSION_H
#define BEAMSIM_VERSION_H
#define BSIM_VERSION "0.1.0"
#endif
