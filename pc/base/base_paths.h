/*
 * base_paths.h - where the installed RoboELF files are: the shared data
 * directory (the DMC programs, the example plant) and the system
 * configuration directory, fixed at build time from the Makefile's PREFIX
 * and SYSCONFDIR (docs/technician.md, "Installation").
 *
 * The environment variable ROBOELF_ROOT, when set and not empty, is put in
 * front of both, as DESTDIR is in front of an installation: it lets a staged
 * installation (make install DESTDIR=DIR) be run where it lies, and is how
 * tests/checks/install.sh tests one. The programs say when it is in force.
 * The module never prints.
 */
#ifndef BASE_PATHS_H
#define BASE_PATHS_H

#include <stddef.h>

/* The root every installed path is looked for under (ROBOELF_ROOT). */
#define BASE_PATHS_ROOT_ENV "ROBOELF_ROOT"

/*
 * base_paths_root() - the value of ROBOELF_ROOT when it is set and not
 * empty, otherwise NULL (the installed paths are used as they are).
 */
const char *base_paths_root(void);

/*
 * base_paths_data() - the installed shared data path of @name.
 * @name: a path relative to the data directory ("dmc", "plant.yaml"), or
 *        "" for the directory itself
 * @out:  out: ROBOELF_ROOT + DATADIR + "/" + @name (DATADIR is
 *        $(PREFIX)/share/roboelf, e.g. /usr/share/roboelf)
 * @len:  size of @out in bytes
 * Return: 0, or -1 when the path does not fit (@out then holds "").
 */
int base_paths_data(const char *name, char *out, size_t len);

/*
 * base_paths_sysconf() - the installed system configuration path of @name.
 * @name: a path relative to SYSCONFDIR ("roboelf/roboelf.yaml")
 * @out:  out: ROBOELF_ROOT + SYSCONFDIR + "/" + @name (SYSCONFDIR is /etc
 *        by default)
 * @len:  size of @out in bytes
 * Return: 0, or -1 when the path does not fit (@out then holds "").
 */
int base_paths_sysconf(const char *name, char *out, size_t len);

/*
 * base_paths_dmc_dir() - the DMC program directory to use when none is
 * given: "dmc" when ./dmc/MANIFEST exists (the source tree), else the
 * installed base_paths_data("dmc") when its MANIFEST exists.
 * @out:     out: the directory chosen, or the installed one when neither
 *           exists (for the message)
 * @len:     size of @out in bytes
 * Return: 0 when a directory with a MANIFEST was found, -1 when none was
 *         (or the path does not fit).
 */
int base_paths_dmc_dir(char *out, size_t len);

/*
 * base_paths_absolute() - @path as an absolute path, for a file the
 * configuration names relative to the directory a program is started in
 * (the log, the calibration file, the traces): printed in full wherever
 * it is named, so that nobody has to know where the program was started.
 * Purely textual: nothing is looked up, ".." and links are left alone.
 * @cwd:  the working directory, absolute (getcwd() at start)
 * @path: an absolute path (copied as it is), a relative one, or "" (copied:
 *        nothing configured)
 * @out:  out: @cwd + "/" + @path, with @path's leading "./" dropped ("."
 *        alone gives @cwd) and no "//" when @cwd is "/"
 * @len:  size of @out in bytes
 * Return: 0, or -1 when @cwd is not absolute or the result does not fit
 *         (@out then holds "").
 */
int base_paths_absolute(const char *cwd, const char *path, char *out,
			size_t len);

#endif /* BASE_PATHS_H */
