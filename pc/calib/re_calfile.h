/*
 * re_calfile.h - calibration tables saved to and loaded from a text file.
 *
 * The format is documented in docs/calibration-file.md: a format version,
 * the controller's serial number, the axes with their names, step, start,
 * soft limits and table values, a hash of the relevant configuration, the
 * date (ISO 8601 UTC) and a CRC-32 of everything before the CRC line.
 *
 * format/parse are pure (buffers only). save writes atomically (temporary
 * file in the same directory, fsync, previous file kept as "<path>.bak",
 * rename, fsync of the directory), so a process killed at any point leaves
 * either the old or the new file at <path>, never a partial one. load refuses
 * anything that does not match this controller and configuration, each case
 * with its own message.
 *
 * Nothing here prints; errors come back as gl_err codes plus a message in the
 * caller's buffer (git style, "FILE:LINE: message" for file content errors).
 */
#ifndef RE_CALFILE_H
#define RE_CALFILE_H

#include <stddef.h>
#include <stdint.h>
#include <time.h>

#include "re_calcheck.h"

#define RE_CALFILE_VERSION   1
#define RE_CAL_NAME_MAX	     16 /* axis name incl. NUL: [A-Za-z0-9_-]{1,15} */
#define RE_CAL_SERIAL_MAX    32 /* serial incl. NUL: printable, no space */
#define RE_CAL_DATE_MAX	     32 /* "2026-05-01T12:34:56Z" incl. NUL */
#define RE_CALFILE_MAX_BYTES (1024 * 1024) /* larger files are refused */

/* A complete calibration: one table per axis plus what it belongs to. */
struct re_calset {
	int n_axes;			/* 1..RE_CAL_MAX_AXES */
	char serial[RE_CAL_SERIAL_MAX]; /* controller serial number */
	uint64_t config_hash;		/* caller's config hash */
	char date[RE_CAL_DATE_MAX];	/* ISO 8601 UTC */
	char name[RE_CAL_MAX_AXES][RE_CAL_NAME_MAX]; /* "A", "B", "C" */
	struct re_caltable axis[RE_CAL_MAX_AXES];
};

/* What a loaded file must match (this controller, this configuration). */
struct re_calfile_expect {
	const char *serial; /* controller serial number */
	int n_axes;
	char name[RE_CAL_MAX_AXES][RE_CAL_NAME_MAX]; /* "" = not checked */
	double step_counts[RE_CAL_MAX_AXES]; /* configured step per axis */
	uint64_t config_hash;
	/* table checks per axis (re_cal_check_table); must be valid, a
	 * zeroed entry makes the parse fail with GL_ERR_ARG */
	struct re_calcheck_cfg check[RE_CAL_MAX_AXES];
};

/*
 * re_calfile_date() - write @t as ISO 8601 UTC "YYYY-MM-DDTHH:MM:SSZ".
 * @buf: [out] at least 21 bytes (RE_CAL_DATE_MAX is enough).
 * Return: GL_OK, GL_ERR_OVERFLOW, GL_ERR_RANGE (gmtime failed).
 */
int re_calfile_date(time_t t, char *buf, size_t cap);

/*
 * re_calfile_format() - the file text for @set (pure).
 * @set: [in] n_axes, serial, date, names, tables (n >= 2) must be valid.
 * @buf: [out] the text, NUL-terminated.
 * @cap: capacity; re_calfile_format_size() bytes are always enough.
 * Return: the length (> 0), GL_ERR_OVERFLOW, or GL_ERR_ARG for an invalid
 *         @set (bad count, empty serial/date/name, characters that the
 *         format cannot carry).
 */
int re_calfile_format(const struct re_calset *set, char *buf, size_t cap);

/* re_calfile_format_size() - an upper bound of the text length + 1 for @set. */
size_t re_calfile_format_size(const struct re_calset *set);

/*
 * re_calfile_parse() - parse and check a file's text (pure).
 * @buf, @len: the whole file content.
 * @filename: used in messages ("FILE:LINE: message").
 * @exp: [in] what the file must match; NULL parses without matching (for
 *       roboelf-tech show-calibration).
 * @out: [out] the calibration; on failure it is cleared (n_axes = 0), never
 *       left half-filled.
 * @err: [out] message on failure (may be NULL); @errlen its size.
 * Return: GL_OK; GL_ERR_FORMAT (syntax, truncated, missing line), GL_ERR_CRC
 *         (checksum), GL_ERR_MISMATCH (serial, axis count, names, step,
 *         config hash), GL_ERR_RANGE (non-monotonic values, range, points,
 *         limits outside the travel), GL_ERR_ARG.
 *         Without @exp only the intrinsic checks run: values strictly
 *         increasing, soft limits inside the travel.
 */
int re_calfile_parse(const char *buf, size_t len, const char *filename,
		     const struct re_calfile_expect *exp, struct re_calset *out,
		     char *err, size_t errlen);

/*
 * re_calfile_save() - write @set to @path atomically, keeping the previous
 * file (if any) as "<path>.bak". Allocates a text buffer (start-up only).
 * Return: GL_OK, GL_ERR_ARG, GL_ERR_NOMEM, GL_ERR_SYS (errno kept; @err
 *         names the file and the failed step). On error @path is unchanged.
 */
int re_calfile_save(const char *path, const struct re_calset *set, char *err,
		    size_t errlen);

/*
 * re_calfile_load() - read @path and re_calfile_parse() it.
 * Return: as re_calfile_parse(), plus GL_ERR_NOENT (missing file: "cannot
 *         open 'PATH': No such file or directory"), GL_ERR_SYS, GL_ERR_NOMEM,
 *         GL_ERR_FORMAT for a file larger than RE_CALFILE_MAX_BYTES.
 */
int re_calfile_load(const char *path, const struct re_calfile_expect *exp,
		    struct re_calset *out, char *err, size_t errlen);

/*
 * Test hook: when set, re_calfile_save() calls it at each step (1 temp file
 * written and synced, 2 backup linked, 3 renamed over @path, 4 directory
 * synced) so a test can kill the process there. NULL in production.
 */
extern void (*re_calfile_save_hook)(int step);

#endif /* RE_CALFILE_H */
