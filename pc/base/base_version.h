/*
 * base_version.h - the release of the RoboELF programs (roboelf,
 * galil-load, galil-sim print it with --version) and the controller
 * program interface they expect: dmc/constants.dmc's `vers`
 * (docs/dmc-interface.md; tests/unit/test_re_dmcif.c holds them equal).
 */
#ifndef BASE_VERSION_H
#define BASE_VERSION_H

#define ROBOELF_VERSION	    "1.4.0"
#define ROBOELF_DMC_VERSION "2.24"

#endif /* BASE_VERSION_H */
