# RoboELF control software - top-level Makefile (GNU make).
#
#   make deps     install the Debian packages the build and tests need
#   make          build build/bin/{roboelf,roboelf-tech,galil-load,galil-sim}
#   make check    build and run every test (the one test command)
#   make asan     the full check built with -fsanitize=address,undefined
#   make demo     the whole system on the simulator
#   make bench    performance figures (printed and written as CSV)
#   make soak     the randomised soak (SOAK_SECONDS, default 600; SOAK_SEED)
#   make lint     clang-format dry run and cppcheck
#   make fuzz     every libFuzzer target for FUZZ_SECONDS (default 600) each
#   make install / uninstall   (PREFIX, DESTDIR)
#   make deb      the Debian packages build/roboelf{,-sim}_<version>_<arch>.deb
#   make fresh    README's two commands in a minimal Debian 12 root (root only)
#   make pkgtest  the two packages installed, used, purged in such a root (root only)
#
# Source layout conventions (so that adding a file needs no Makefile edit):
#   pc/base/*.c          shared base: clock, files, YAML -> $(BUILD)/lib/libbase.a
#   pc/galil/*.c         Galil link library (gl_*)       -> $(BUILD)/lib/libgl.a
#   pc/dmc/*.c           the DMC language front end      -> $(BUILD)/lib/libdmc.a
#   pc/super/*.c         the safety core: the cycle, its checks, the fault
#                        reaction, the relay, the log, the locks, real time
#                                                         -> $(BUILD)/lib/libsuper.a
#   pc/{config,calib,rec,console,start}/*.c  the rest of the supervisor:
#                        configuration and plan, calibration, recorder and
#                        traces, console, start-up -> libre.a
#   pc/roboelf.c         supervisor main                 -> $(BUILD)/bin/roboelf
#   tools/galil-sim/**.c simulator (main.c = main)       -> libsim.a + galil-sim
#                        (ctrl/ the interpreter, plant/ the robot, net/ the ports)
#   tools/galil-load/*.c loader (main.c = main)          -> libload.a + galil-load
#   tools/roboelf-tech/*.c the technician's program: commissioning, viewers,
#                        host check (main.c = main)      -> libtech.a + roboelf-tech
#   tests/harness/*.c    test helpers                    -> libharness.a
#   tests/stub/*.c       the misbehaving socket stub     -> $(BUILD)/bin/galil-stub
#   tests/<dir>/test_*.c one cmocka binary each          -> $(BUILD)/tests/<dir>/test_*
#     linked with: libload libsim libre libsuper libdmc libgl libbase libharness (only
#     what is used is pulled in), plus extra linker flags from an optional
#     tests/<dir>/test_*.ldflags file (e.g. -Wl,--wrap=sp_open).
# Layering (checked by tests/checks/layers.sh): base <- galil, dmc <- super <- config
# <- calib, rec <- console <- start <- roboelf, roboelf-tech;
# base, galil, dmc <- galil-load and galil-sim; nothing includes upward.

CC ?= cc
CFLAGS ?= -O2 -g
PREFIX ?= /usr/local
SYSCONFDIR ?= /etc
DESTDIR ?=
INSTALL ?= install
BUILD ?= build

WARN = -std=c11 -Wall -Wextra -Wpedantic -Wshadow -Wstrict-prototypes \
       -Wmissing-prototypes -Wformat=2 -Wvla -Wwrite-strings
ifeq ($(DEVELOPER),1)
WARN += -Werror
endif

PKGS = libserialport yaml-0.1 cmocka
PKG_CFLAGS := $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
PKG_LIBS := $(shell pkg-config --libs $(PKGS) 2>/dev/null)

ifdef SANITIZE
SAN = -fsanitize=$(SANITIZE) -fno-sanitize-recover=$(SANITIZE) -fno-omit-frame-pointer
endif

ALL_CFLAGS = $(WARN) $(CFLAGS) $(SAN) -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE \
             $(addprefix -I,$(INC_DIRS)) $(PKG_CFLAGS) -MMD -MP
ALL_LDFLAGS = $(LDFLAGS) $(SAN)
LIBS = $(PKG_LIBS) -lpthread -lm

SIM_DIRS := tools/galil-sim $(wildcard tools/galil-sim/*/)
RE_DIRS := pc/config pc/calib pc/rec pc/console pc/start
INC_DIRS := pc $(wildcard pc/base pc/galil pc/dmc) pc/super $(RE_DIRS) $(patsubst %/,%,$(SIM_DIRS)) \
            tools/galil-load tools/roboelf-tech tests/harness tests/stub

BASE_SRC := $(wildcard pc/base/*.c)
GL_SRC := $(wildcard pc/gl_*.c pc/galil/*.c)
DMC_SRC := $(wildcard pc/dmc/*.c)
SUPER_SRC := $(wildcard pc/super/*.c)
RE_SRC := $(wildcard $(addsuffix /*.c,$(RE_DIRS)))
SIM_SRC := $(filter-out tools/galil-sim/main.c,$(wildcard $(addsuffix /*.c,$(patsubst %/,%,$(SIM_DIRS)))))
LOAD_SRC := $(filter-out tools/galil-load/main.c,$(wildcard tools/galil-load/*.c))
TECH_SRC := $(filter-out tools/roboelf-tech/main.c,$(wildcard tools/roboelf-tech/*.c))
HARN_SRC := $(wildcard tests/harness/*.c)
STUB_SRC := $(wildcard tests/stub/*.c)
TEST_SRC := $(wildcard tests/*/test_*.c)

obj = $(patsubst %.c,$(BUILD)/obj/%.o,$(1))
LIB_BASE := $(if $(BASE_SRC),$(BUILD)/lib/libbase.a)
LIB_GL := $(BUILD)/lib/libgl.a
LIB_DMC := $(if $(DMC_SRC),$(BUILD)/lib/libdmc.a)
LIB_SUPER := $(BUILD)/lib/libsuper.a
LIB_RE := $(BUILD)/lib/libre.a
LIB_SIM := $(BUILD)/lib/libsim.a
LIB_LOAD := $(BUILD)/lib/libload.a
LIB_TECH := $(BUILD)/lib/libtech.a
LIB_HARN := $(BUILD)/lib/libharness.a
LINK_LIBS := $(LIB_HARN) $(LIB_TECH) $(LIB_LOAD) $(LIB_SIM) $(LIB_RE) $(LIB_SUPER) $(LIB_DMC) $(LIB_GL) \
             $(LIB_BASE)

BINS := $(if $(wildcard pc/roboelf.c),$(BUILD)/bin/roboelf) \
        $(if $(wildcard tools/galil-load/main.c),$(BUILD)/bin/galil-load) \
        $(if $(wildcard tools/roboelf-tech/main.c),$(BUILD)/bin/roboelf-tech) \
        $(if $(wildcard tools/galil-sim/main.c),$(BUILD)/bin/galil-sim) \
        $(if $(STUB_SRC),$(BUILD)/bin/galil-stub)
TESTS := $(patsubst tests/%.c,$(BUILD)/tests/%,$(TEST_SRC))

.PHONY: all check test asan demo bench soak lint install uninstall clean deps tests
.SUFFIXES:
.DELETE_ON_ERROR:

all: $(BINS)

tests: $(BINS) $(TESTS)

$(BUILD)/obj/%.o: %.c | have-deps
	@mkdir -p $(@D)
	$(CC) $(ALL_CFLAGS) -c $< -o $@

define mklib
$(1): $(call obj,$(2))
	@mkdir -p $$(@D)
	@rm -f $$@
	$$(AR) rcs $$@ $$^
endef
$(if $(LIB_BASE),$(eval $(call mklib,$(LIB_BASE),$(BASE_SRC))))
$(eval $(call mklib,$(LIB_GL),$(GL_SRC)))
$(if $(LIB_DMC),$(eval $(call mklib,$(LIB_DMC),$(DMC_SRC))))
$(eval $(call mklib,$(LIB_SUPER),$(SUPER_SRC)))
$(eval $(call mklib,$(LIB_RE),$(RE_SRC)))
$(eval $(call mklib,$(LIB_SIM),$(SIM_SRC)))
$(eval $(call mklib,$(LIB_LOAD),$(LOAD_SRC)))
$(eval $(call mklib,$(LIB_TECH),$(TECH_SRC)))
$(eval $(call mklib,$(LIB_HARN),$(HARN_SRC)))

$(BUILD)/bin/roboelf: $(call obj,pc/roboelf.c) $(LIB_RE) $(LIB_SUPER) $(LIB_DMC) $(LIB_GL) $(LIB_BASE)
	@mkdir -p $(@D)
	$(CC) $(ALL_LDFLAGS) -o $@ $^ $(LIBS)
$(BUILD)/bin/galil-load: $(call obj,tools/galil-load/main.c) $(LIB_LOAD) $(LIB_RE) $(LIB_SUPER) $(LIB_DMC) $(LIB_GL) \
		$(LIB_BASE)
	@mkdir -p $(@D)
	$(CC) $(ALL_LDFLAGS) -o $@ $^ $(LIBS)
$(BUILD)/bin/roboelf-tech: $(call obj,tools/roboelf-tech/main.c) $(LIB_TECH) $(LIB_RE) $(LIB_SUPER) $(LIB_DMC) \
		$(LIB_GL) $(LIB_BASE)
	@mkdir -p $(@D)
	$(CC) $(ALL_LDFLAGS) -o $@ $^ $(LIBS)
$(BUILD)/bin/galil-sim: $(call obj,tools/galil-sim/main.c) $(LIB_SIM) $(LIB_RE) $(LIB_SUPER) $(LIB_DMC) $(LIB_GL) \
		$(LIB_BASE)
	@mkdir -p $(@D)
	$(CC) $(ALL_LDFLAGS) -o $@ $^ $(LIBS)
$(BUILD)/bin/galil-stub: $(call obj,$(STUB_SRC)) $(LIB_GL) $(LIB_BASE)
	@mkdir -p $(@D)
	$(CC) $(ALL_LDFLAGS) -o $@ $^ $(LIBS)

# Each test: its object, the libraries, and optional extra linker flags.
.SECONDEXPANSION:
$(BUILD)/tests/%: $(BUILD)/obj/tests/%.o $(LINK_LIBS) $$(wildcard tests/$$*.ldflags)
	@mkdir -p $(@D)
	$(CC) $(ALL_LDFLAGS) $(shell cat tests/$*.ldflags 2>/dev/null) -o $@ $< \
		$(LINK_LIBS) $(LIBS)

# ---- test, demo, bench -------------------------------------------------------
# The build first, on every core.
check test: deps
	@$(MAKE) --no-print-directory -j$$(nproc) tests
	@BUILD=$(BUILD) tests/run-all.sh

# The sanitizer run looks for memory and undefined-behaviour errors: every
# test program again, the soak for 20 s instead of 60, and the checks that do
# not run the sanitized programs only once, in make check (tests/run-all.sh).
asan: deps
	@ROBOELF_SAN=1 ROBOELF_SOAK_S=$${ROBOELF_SOAK_S:-20} $(MAKE) --no-print-directory \
		BUILD=$(BUILD)/asan SANITIZE=address,undefined CFLAGS="-O1 -g" check

# The scripts run with only the commands of docs/commands.md on their PATH
# (tools/cmdtable.sh), as the tests do (tests/run-all.sh).
CMDPATH = $(CURDIR)/$(BUILD)/cmdpath
.PHONY: cmdpath fresh pkgtest
cmdpath:
	@sh tools/cmdtable.sh path $(CMDPATH)

demo: deps
	@$(MAKE) --no-print-directory all cmdpath
	@BUILD=$(BUILD) INTERACTIVE=$(INTERACTIVE) PATH=$(CMDPATH) tools/demo.sh

bench: deps
	@$(MAKE) --no-print-directory tests cmdpath
	@BUILD=$(BUILD) PATH=$(CMDPATH) tests/bench.sh

# README's two commands in a minimal Debian 12 root, the current commit
# cloned into it (root only; SKIPPED otherwise; tools/fresh.sh)
fresh: deps
	@$(MAKE) --no-print-directory cmdpath
	@BUILD=$(BUILD) ROBOELF_SYSPATH="$$PATH" PATH=$(CMDPATH) sh tools/fresh.sh

# The two Debian packages installed, used and purged in a copy of that
# Debian 12 root (root only; SKIPPED otherwise; tests/pkg/pkgtest.sh;
# ROBOELF_DEBROOT: where the pristine root is kept, default $(BUILD)/fresh)
pkgtest: deps
	@$(MAKE) --no-print-directory cmdpath
	@BUILD=$(BUILD) ROBOELF_SYSPATH="$$PATH" PATH=$(CMDPATH) sh tests/pkg/pkgtest.sh

# The soak: seeded random joystick use with pot noise and transient invalid
# states (tests/system/test_sys_soak.c); make check runs it for 60 s.
SOAK_SECONDS ?= 600
SOAK_SEED ?= 20261125
soak: deps
	@$(MAKE) --no-print-directory tests cmdpath
	@BUILD=$(BUILD) PATH=$(CMDPATH) ROBOELF_BIN=$(CURDIR)/$(BUILD)/bin ROBOELF_TOP=$(CURDIR) \
		ROBOELF_SOAK_S=$(SOAK_SECONDS) ROBOELF_SOAK_SEED=$(SOAK_SEED) \
		$(BUILD)/tests/system/test_sys_soak

lint: have-lint-deps
	$(CLANG_FORMAT) --dry-run --Werror $(shell git ls-files '*.c' '*.h' 2>/dev/null)
	$(CPPCHECK) --quiet --error-exitcode=1 --std=c11 --enable=warning,portability \
		--suppress=missingIncludeSystem $(addprefix -I,$(INC_DIRS)) \
		pc tools tests

# ---- fuzzing (docs/fuzzing.md) -----------------------------------------------
# One libFuzzer target per tests/fuzz/fuzz_<name>.c, built with clang and
# -fsanitize=fuzzer,address,undefined into $(FUZZ_BUILD) (its own libraries,
# never the normal objects). `make fuzz` runs each for FUZZ_SECONDS on a copy
# of tests/fuzz/corpus/<name> + regress/<name> kept in $(FUZZ_BUILD)/corpus
# (the repository's corpus is never written); `make check` runs each for a
# few seconds (tests/checks/fuzz_short.sh).
FUZZ_CC ?= clang
FUZZ_SECONDS ?= 600
FUZZ_BUILD ?= $(BUILD)/fuzz
FUZZ_SAN = -fsanitize=fuzzer,address,undefined \
           -fno-sanitize-recover=address,undefined -fno-omit-frame-pointer
FUZZ_NAMES := $(patsubst tests/fuzz/fuzz_%.c,%,$(wildcard tests/fuzz/fuzz_*.c))
FUZZ_BINS := $(addprefix $(FUZZ_BUILD)/bin/fuzz_,$(FUZZ_NAMES))
FUZZ_LIBS := $(patsubst $(BUILD)/%,$(FUZZ_BUILD)/%,$(LIB_LOAD) $(LIB_SIM) \
             $(LIB_RE) $(LIB_SUPER) $(LIB_DMC) $(LIB_GL) $(LIB_BASE))
.PHONY: fuzz fuzz-build
fuzz: deps
	@$(MAKE) --no-print-directory fuzz-build cmdpath
	@FUZZ_BUILD=$(FUZZ_BUILD) FUZZ_SECONDS=$(FUZZ_SECONDS) PATH=$(CMDPATH) \
		tests/fuzz/run.sh $(FUZZ_NAMES)
fuzz-build:
	@$(MAKE) --no-print-directory BUILD=$(FUZZ_BUILD) CC=$(FUZZ_CC) \
		SANITIZE=address,undefined CFLAGS="-O1 -g -fsanitize=fuzzer-no-link" \
		$(FUZZ_LIBS)
	@$(MAKE) --no-print-directory $(FUZZ_BINS)
$(FUZZ_BUILD)/bin/fuzz_%: tests/fuzz/fuzz_%.c $(FUZZ_LIBS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(WARN) -O1 -g $(FUZZ_SAN) -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE \
		$(addprefix -I,$(INC_DIRS)) $(PKG_CFLAGS) -MMD -MP -MF $@.d -o $@ $< \
		$(FUZZ_LIBS) $(LIBS)
-include $(wildcard $(FUZZ_BUILD)/bin/*.d)

# ---- dependencies ------------------------------------------------------------
# Every command that make check, demo, bench, fresh and the package's scripts
# call has its package here or is Essential (docs/commands.md, the one table;
# tests/checks/commands.sh holds the two together).
DEB_PKGS = gcc make binutils pkgconf libserialport-dev libyaml-dev libcmocka-dev \
           gnuplot-nox tmux clang-format cppcheck clang libclang-rt-dev valgrind strace \
           procps iproute2 shfmt jq git debootstrap
deps:
	@missing=""; for p in $(DEB_PKGS); do \
		dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
		if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
			echo "deps: installing$$missing"; \
			apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing >/dev/null || exit 1; \
		else \
			echo "deps: missing Debian packages:$$missing"; \
			echo "deps: run: sudo apt-get install$$missing"; exit 1; \
		fi; \
	fi

.PHONY: print-deb-pkgs
print-deb-pkgs:
	@echo $(DEB_PKGS)

# ---- network rig (tests/net, docs/link.md) ------------------------------------
# nfq-delay (the rig's packet delayer) is built when libnetfilter-queue is
# there; `make netrig` runs every network case (minutes), `make check` the
# short ones. Skipped without root: reported SKIPPED, and netrig fails.
DEB_PKGS += iptables libnetfilter-queue-dev
NFQ_LIBS := $(shell pkg-config --libs libnetfilter_queue 2>/dev/null)
ifneq ($(NFQ_LIBS),)
tests: $(BUILD)/bin/nfq-delay
$(BUILD)/bin/nfq-delay: tests/net/nfq_delay.c
	@mkdir -p $(@D)
	$(CC) $(WARN) $(CFLAGS) $(SAN) -D_DEFAULT_SOURCE $(ALL_LDFLAGS) -o $@ $< $(NFQ_LIBS)
endif
.PHONY: netrig
netrig: deps
	@$(MAKE) --no-print-directory tests
	@BUILD=$(BUILD) ROBOELF_NETRIG=long ROBOELF_NO_SKIP=1 tests/run-all.sh net

# ---- install -----------------------------------------------------------------
# The installed places: base_paths.c is built with DATADIR and
# SYSCONFDIR (and rebuilt when they change); roboelf, roboelf-tech and
# galil-load look there for what is not in the directory they are started
# in (docs/technician.md, "Installation"). The docs tree is installed as it is, links intact.
DATADIR = $(PREFIX)/share/roboelf
DOCDIR = $(PREFIX)/share/doc/roboelf
MAN1 := $(wildcard docs/*.1)
MAN5 := $(wildcard docs/*.5)
# The developer's documents (the code's layout, the command table, fuzzing,
# the man pages' sources: read with man) stay in the source tree.
DEV_DOCS := docs/architecture.md docs/commands.md docs/fuzzing.md $(MAN1) $(MAN5)
DOC_FILES := $(filter-out $(DEV_DOCS),$(shell find docs -type f ! -name '.*' 2>/dev/null | \
	LC_ALL=C sort))
# The site's state (the clinical template's paths): the calibration files
# and the log with the traces, shared by the operators' group roboelf.
STATE_DIRS := /var/lib/roboelf /var/log/roboelf
STATE_GROUP := roboelf
PATHS_STAMP := $(BUILD)/gen/paths
$(call obj,pc/base/base_paths.c): ALL_CFLAGS += -DROBOELF_DATADIR='"$(DATADIR)"' \
	-DROBOELF_SYSCONFDIR='"$(SYSCONFDIR)"'
$(call obj,pc/base/base_paths.c): $(PATHS_STAMP)
$(PATHS_STAMP): paths-force
	@mkdir -p $(@D); echo '$(DATADIR) $(SYSCONFDIR)' >$@.new; \
	if cmp -s $@.new $@; then rm $@.new; else mv $@.new $@; fi
.PHONY: paths-force

install: all
	$(INSTALL) -d "$(DESTDIR)$(PREFIX)/bin" "$(DESTDIR)$(PREFIX)/share/man/man1" \
		"$(DESTDIR)$(PREFIX)/share/man/man5" "$(DESTDIR)$(DATADIR)/dmc" \
		"$(DESTDIR)$(DATADIR)/config" "$(DESTDIR)$(DOCDIR)"
	$(INSTALL) -m 755 $(BINS:$(BUILD)/bin/galil-stub=) "$(DESTDIR)$(PREFIX)/bin/"
	$(if $(MAN1),$(INSTALL) -m 644 $(MAN1) "$(DESTDIR)$(PREFIX)/share/man/man1/")
	$(if $(MAN5),$(INSTALL) -m 644 $(MAN5) "$(DESTDIR)$(PREFIX)/share/man/man5/")
	$(INSTALL) -m 644 $(wildcard dmc/*.dmc dmc/MANIFEST) "$(DESTDIR)$(DATADIR)/dmc/"
	$(INSTALL) -m 644 $(wildcard config/*.yaml) "$(DESTDIR)$(DATADIR)/config/"
	@# the operator's configuration roboelf finds without -c: the site
	@# template, refused until the technician fills it in (the development
	@# configuration stays in the source tree); an existing (edited) one is kept
	$(INSTALL) -d "$(DESTDIR)$(SYSCONFDIR)/roboelf"
	[ -e "$(DESTDIR)$(SYSCONFDIR)/roboelf/roboelf.yaml" ] || \
		$(INSTALL) -m 644 config/roboelf-site.yaml "$(DESTDIR)$(SYSCONFDIR)/roboelf/roboelf.yaml"
	@# the site's state: 2770 root:roboelf (setgid: what roboelf writes
	@# there belongs to the group); the group is given when it exists and
	@# this is root (the package's postinst makes it), else said
	$(INSTALL) -d -m 2770 $(addprefix "$(DESTDIR),$(addsuffix ",$(STATE_DIRS)))
	@if [ "$$(id -u)" = 0 ] && getent group $(STATE_GROUP) >/dev/null; then \
		chgrp $(STATE_GROUP) $(addprefix "$(DESTDIR),$(addsuffix ",$(STATE_DIRS))) || exit 1; \
	else echo "install: $(STATE_DIRS) are not the operators' yet: as root," \
		"groupadd --system $(STATE_GROUP); chgrp $(STATE_GROUP) $(STATE_DIRS)" \
		"(docs/technician.md, \"Installation\")"; fi
	$(INSTALL) -m 755 tools/demo.sh "$(DESTDIR)$(DATADIR)/demo.sh"
	@# the link's ifupdown hook: rto_min on the controller's route
	@# (docs/link.md); an existing (edited) one is kept
	$(INSTALL) -d "$(DESTDIR)$(SYSCONFDIR)/network/if-up.d"
	[ -e "$(DESTDIR)$(SYSCONFDIR)/network/if-up.d/roboelf" ] || \
		$(INSTALL) -m 755 packaging/ifupdown/roboelf "$(DESTDIR)$(SYSCONFDIR)/network/if-up.d/roboelf"
	$(INSTALL) -m 644 README.md "$(DESTDIR)$(DOCDIR)/"
	@for f in $(DOC_FILES); do \
		$(INSTALL) -D -m 644 "$$f" "$(DESTDIR)$(DOCDIR)/$$f" || exit 1; done

uninstall:
	rm -f $(addprefix "$(DESTDIR)$(PREFIX)/bin/",roboelf roboelf-tech galil-load galil-sim)
	rm -f $(addprefix "$(DESTDIR)$(PREFIX)/share/man/man1/",$(notdir $(MAN1)))
	rm -f $(addprefix "$(DESTDIR)$(PREFIX)/share/man/man5/",$(notdir $(MAN5)))
	rm -rf "$(DESTDIR)$(DATADIR)" "$(DESTDIR)$(DOCDIR)"
	@# the site's calibration, log and traces are kept; only empty
	@# directories go
	-rmdir $(addprefix "$(DESTDIR),$(addsuffix ",$(STATE_DIRS))) 2>/dev/null

# ---- missing packages and the Debian package ---------------------
# have-deps: before compiling, name the missing Debian packages and `make deps`
# (tools/have-deps.sh) instead of a raw compiler error; have-lint-deps: the
# same for make lint. make deb: the programs built again with the Debian build
# flags into $(BUILD)/deb, installed there with PREFIX=/usr, packaged by
# dpkg-deb with packaging/deb/ (tools/mkdeb.sh): $(BUILD)/roboelf_V_ARCH.deb.
PKG_CONFIG ?= pkg-config
CLANG_FORMAT ?= clang-format
CPPCHECK ?= cppcheck
DEB_PKGS += dpkg-dev lintian
.PHONY: have-deps have-lint-deps deb
have-deps:
	@CC="$(CC)" PKG_CONFIG="$(PKG_CONFIG)" sh tools/have-deps.sh build
have-lint-deps:
	@CLANG_FORMAT="$(CLANG_FORMAT)" CPPCHECK="$(CPPCHECK)" sh tools/have-deps.sh lint
deb: have-deps
	@BUILD="$(BUILD)" MAKE="$(MAKE)" sh tools/mkdeb.sh

clean:
	rm -rf $(BUILD)

-include $(shell find $(BUILD)/obj -name '*.d' 2>/dev/null)
