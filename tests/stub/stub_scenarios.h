/*
 * stub_scenarios.h - the magic commands of galil-stub and the fixed values
 * it reports, shared by the stub and the tests (the libmodbus "magic
 * address" pattern).
 *
 * A magic command is sent as an ordinary command line and answered ':'. It
 * changes how the stub answers the NEXT command line on the same connection
 * (one shot), except SILENT (for good) and MSG (at once). The same words,
 * without "STUB ", may be given on the stub's command line; they then apply
 * to every new connection, as if sent first.
 */
#ifndef STUB_SCENARIOS_H
#define STUB_SCENARIOS_H

#define STUB_PREFIX "STUB "

/* STUB DELAY <ms>: answer the next line after <ms> milliseconds. */
#define STUB_DELAY "STUB DELAY"
/* STUB QMARK: reject the first command of the next line with '?', TC 1. */
#define STUB_QMARK "STUB QMARK"
/* STUB SPLIT1: write the next reply byte by byte, 1 ms apart. */
#define STUB_SPLIT1 "STUB SPLIT1"
/* STUB CHUNKS: write the next reply in random chunks of 1..8 bytes. */
#define STUB_CHUNKS "STUB CHUNKS"
/*
 * STUB COALESCE: write the replies of all commands of the next line (and a
 * DL's two acknowledgements) in one write(). By default the stub writes each
 * command's reply separately, STUB_GAP_MS apart, so that the client sees
 * them in separate reads.
 */
#define STUB_COALESCE "STUB COALESCE"
/* STUB GARBAGE: answer the next line with STUB_GARBAGE_BYTES instead. */
#define STUB_GARBAGE "STUB GARBAGE"
/* STUB UNSOL: put STUB_UNSOL_TEXT, high bit set, in the middle of the next
 * reply (inside the binary record for "x=1;QR"). */
#define STUB_UNSOL "STUB UNSOL"
/* STUB UNSOLPRE: put STUB_UNSOL_TEXT, high bit set, just before the reply
 * of the last command of the next line (before a QR record). */
#define STUB_UNSOLPRE "STUB UNSOLPRE"
/*
 * STUB EXTRA [ms]: after the reply to the next line send one more ':' (a
 * duplicated terminator) - in the same write, or <ms> milliseconds later.
 */
#define STUB_EXTRA "STUB EXTRA"
/* STUB DROP: close the connection when the next line arrives. */
#define STUB_DROP "STUB DROP"
/* STUB SILENT: from now on read everything, answer nothing (half-open). */
#define STUB_SILENT "STUB SILENT"
/* STUB DLREJECT <n>: answer '?' to line n of the next DL (TC 60) and keep
 * the old program. */
#define STUB_DLREJECT "STUB DLREJECT"
/* STUB MSG <text>: send <text> CR LF as an unsolicited message to the
 * handle chosen by CF (high bit set after CW1); dropped if CF is unset. */
#define STUB_MSG "STUB MSG"
/* STUB MSGCLOSE: close the connection that CF points to. */
#define STUB_MSGCLOSE "STUB MSGCLOSE"
/* STUB BADHDR: the next QR record announces 4 axes in its header (length
 * and everything else unchanged). */
#define STUB_BADHDR "STUB BADHDR"

#define STUB_GAP_MS	   2 /* between command replies of a line */
#define STUB_GARBAGE_BYTES "\x01\x02garbage\x00\x1f:"
#define STUB_UNSOL_TEXT	   "STUB UNSOLICITED 42"

/* What the stub reports. */
#define STUB_MODEL	     "DMC4030 Rev 1.2h" /* ^R^V */
#define STUB_SERIAL	     12345		/* MG _BN */
#define STUB_QZ		     " 3, 52, 26, 36" /* a DMC-4030: 190-byte record */
#define STUB_TC_UNKNOWN	     1
#define STUB_TC_UNKNOWN_TEXT "Unrecognized command"
#define STUB_TC_DL	     60
#define STUB_TC_DL_TEXT	     "Download error - line too long or too many lines"

/*
 * The QR record (layout 4000, 3 axes). sample = number of QRs served on all
 * connections; ZA of axis A = the variable hbpc (0 if unset), so a test can
 * see that "hbpc=n;QR" executed the prefix first.
 */
#define STUB_REC_POS_A	 1000 /* motor_pos, counts */
#define STUB_REC_POS_B	 (-2000)
#define STUB_REC_POS_C	 3000
#define STUB_REC_ZA_B	 1234567
#define STUB_REC_ZA_C	 (-7)
#define STUB_REC_THREADS 0x03
#define STUB_REC_INPUTS0 0xA5

#endif /* STUB_SCENARIOS_H */
