/*
**  runfile.h - host-side reader of telescope pointing runs.
**
**  Reads a pointing run (a list of observed stars with the encoder readings
**  of the mount at each) from one of seven formats, detected from the
**  content (or forced with pmrun_options.format):
**
**     PMRUN_FORMAT_FOUR_COLUMN  "tau delta T D" per line, degrees
**                               (Pal et al., Exp Astron 2016, the FITSH
**                               example format)
**     PMRUN_FORMAT_NAMED        the same with a "# tau delta T D ..." header
**                               naming the columns, extra known columns
**                               (pier temp time dir) and auxiliary ones
**     PMRUN_FORMAT_TPOINT       TPOINT data files (equatorial or alt-az);
**                               equatorial catalogue places are reduced to
**                               observed hour angle and declination with
**                               ERFA
**     PMRUN_FORMAT_RTS2         RTS2 gpoint input files (MJD, LST, mount
**                               and true RA/Dec or alt-az per line)
**     PMRUN_FORMAT_MW4          MountWizzard4 (10Micron) model files: a
**                               JSON list of points (mount and solved JNow
**                               places, sidereal time, pier side, time)
**     PMRUN_FORMAT_CSV          N.I.N.A./ASCOM-style CSV logs with named
**                               columns (mount and solved RA/Dec, pier side,
**                               time or LST; J2000 reduced with ERFA)
**     PMRUN_FORMAT_MMT          the MMT mount computer's pointing log
**                               (13 'KEY: values' lines per star; pytelpoint)
**
**  docs/formats.md describes every format, column, convention and message.
**
**  All angles are radians.  Other units are in the name (_deg, _c, _h, _m).
**  The reader owns its memory: pmrun_read allocates one pmrun, pmrun_free
**  releases it and everything the accessors returned.  The API is plain C
**  (C89 compatible) and reentrant: no globals, no static state.
*/
#ifndef PMRUN_RUNFILE_H
#define PMRUN_RUNFILE_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Longest line accepted, in bytes (without the line end). */
#ifndef PMRUN_MAX_LINE
#define PMRUN_MAX_LINE 65536
#endif

/* Most records one file may hold. */
#ifndef PMRUN_MAX_RECORDS
#define PMRUN_MAX_RECORDS 1000000
#endif

/* Most auxiliary (unknown named) columns. */
#define PMRUN_MAX_AUX 8

/* Most warning / skipped-record messages kept (the counts go on). */
#ifndef PMRUN_MAX_MESSAGES
#define PMRUN_MAX_MESSAGES 1000
#endif

/* Status codes of pmrun_read: 0 success, negative error. */
enum pmrun_status {
    PMRUN_OK = 0,
    PMRUN_ERR_ARG = -1,      /* NULL path or out pointer */
    PMRUN_ERR_IO = -2,       /* cannot open or read the file */
    PMRUN_ERR_FORMAT = -3,   /* malformed content (message says where) */
    PMRUN_ERR_NOMEM = -4     /* out of memory */
};

/* File formats (pmrun_format). */
enum pmrun_format_id {
    PMRUN_FORMAT_FOUR_COLUMN = 0,
    PMRUN_FORMAT_NAMED = 1,
    PMRUN_FORMAT_TPOINT = 2,
    PMRUN_FORMAT_RTS2 = 3,
    PMRUN_FORMAT_MW4 = 4,
    PMRUN_FORMAT_CSV = 5,
    PMRUN_FORMAT_MMT = 6
};

/* pmrun_options.format: detect the format from the content. */
#define PMRUN_FORMAT_AUTO (-1)

/* pmrun_options.equinox: the equinox of the RA/Dec places of the formats
** that give them (CSV logs, RTS2 gpoint files). */
enum pmrun_equinox_id {
    PMRUN_EQUINOX_FILE = 0,   /* as the file states it (or the format's rule) */
    PMRUN_EQUINOX_J2000 = 1,  /* J2000 mean places (ICRS): reduced with ERFA */
    PMRUN_EQUINOX_JNOW = 2    /* apparent places of date: no reduction */
};

/* Mount types (pmrun_mount). */
enum pmrun_mount_id {
    PMRUN_MOUNT_EQUATORIAL = 0,
    PMRUN_MOUNT_ALTAZ = 1
};

/* Pier side (pmrun_obs.pier). */
enum pmrun_pier_id {
    PMRUN_PIER_WEST = -1,    /* beyond the pole (ASCOM pierWest)    */
    PMRUN_PIER_UNKNOWN = 0,  /* not known, or an alt-az mount       */
    PMRUN_PIER_EAST = 1      /* normal side (ASCOM pierEast)        */
};

/*
**  pmrun_obs - one observation of a pointing run.
**
**  Axis 1 / axis 2 are hour angle / declination for an equatorial mount and
**  azimuth / elevation for an alt-az mount.  Azimuth is always measured from
**  north through east (the ERFA convention: N = 0, E = pi/2), whatever the
**  file used.
**
**     enc_ha    double   encoder axis 1 (radians), reduced into (-pi, pi]
**                        (TPOINT equatorial: LST - raw RA)
**     enc_dec   double   encoder axis 2 (radians), reduced into (-pi, pi]:
**                        a declination beyond +-pi/2 means the telescope
**                        is beyond the pole (a flipped German mount's
**                        194.17 deg and -165.83 deg are the same reading)
**     app_ha    double   apparent (observed) axis 1 of the star (radians):
**                        HA in (-pi, pi], azimuth in [0, 2pi)
**     app_dec   double   apparent (observed) axis 2 of the star (radians)
**     pier      int      PMRUN_PIER_EAST (+1), _WEST (-1), _UNKNOWN (0):
**                        from the pier column if there is one, else for an
**                        equatorial mount -1 if |enc_dec| > pi/2, else +1;
**                        always 0 for alt-az without a pier column
**     temp_c    double   air temperature (deg C), NaN when absent; TPOINT:
**                        the run line's temperature
**     time_h    double   time (hours), NaN when absent; TPOINT equatorial:
**                        estimated UTC hours since 0h of the run date
**                        (docs/formats.md, "time of each record")
**     dir       int      +1/-1 direction of the last slew on axis 1,
**                        0 unknown
**     line      int      1-based line number in the file
**     aux       double[] auxiliary columns in the order of pmrun_aux_name,
**                        NaN when absent
**     enc_raw   double[2] the encoder axes as the file wrote them, before
**                        the reduction (radians; the turn of a cable wrap,
**                        a controller's 0..360 deg writing)
**
**  Encoder angles are modular: the readers accept any finite value and
**  reduce it exactly (in degrees, before the conversion to radians), so a
**  run written with encoder angles in 0..360 deg and the same run in
**  -180..180 deg read the same (docs/formats.md, "Ranges").
*/
typedef struct pmrun_obs {
    double enc_ha, enc_dec;
    double app_ha, app_dec;
    int pier;
    double temp_c, time_h;
    int dir;
    int line;
    double aux[PMRUN_MAX_AUX];
    double enc_raw[2];
} pmrun_obs;

/*
**  pmrun_options - how pmrun_read reads and reduces a file.
**
**  Always start from pmrun_options_default (a zeroed struct turns
**  refraction off and overrides the pressure with 0).
**
**     refraction     int     1 (default): apply refraction in the TPOINT
**                            equatorial reduction; 0: leave it out
**     skip_bad       int     0 (default): the first bad record is an
**                            error; 1: skip bad records, report each one
**                            in the warnings and the skipped list
**     pressure_hpa   double  NaN (default): the file's pressure; else use
**                            this one (hPa) for the reduction
**     temp_c         double  NaN (default), or an override (deg C)
**     humidity       double  NaN (default), or an override (0-1)
**     wavelength_um  double  NaN (default), or an override (micrometres)
**     format         int     PMRUN_FORMAT_AUTO (default): detect the
**                            format from the content; or a PMRUN_FORMAT_*
**                            id: read the file as that format
**     equinox        int     PMRUN_EQUINOX_FILE (default): as the file
**                            says; PMRUN_EQUINOX_J2000 / _JNOW: override
**                            (CSV logs and RTS2 gpoint files only)
**
**  The weather options change the reductions (TPOINT equatorial, CSV and
**  RTS2 J2000 places, CSV refraction); where no reduction refracts, a
**  warning says they were not used.  skip_bad and format apply to every
**  format.  A zeroed struct (instead of pmrun_options_default) forces the
**  four-column format.
*/
typedef struct pmrun_options {
    int refraction;
    int skip_bad;
    double pressure_hpa;
    double temp_c;
    double humidity;
    double wavelength_um;
    int format;
    int equinox;
} pmrun_options;

/*
**  pmrun_site - the run line of a TPOINT file (or the metadata of a
**  column file): what was read, after the options' overrides and the
**  percent-to-fraction conversion of the humidity.  NaN (or 0 for the
**  date) when absent; defaults the reduction used are not filled in.
*/
typedef struct pmrun_site {
    double latitude_rad;
    double height_m;
    double pressure_hpa;
    double temp_c;
    double humidity;
    double wavelength_um;
    double lapse_k_per_m;
    int year, month, day;
} pmrun_site;

/* A pointing run read from a file (opaque). */
typedef struct pmrun pmrun;

/*
**  pmrun_options_default - fill in the default options.
**
**  Returned:
**     opt      pmrun_options*  refraction 1, skip_bad 0, overrides NaN,
**                              format PMRUN_FORMAT_AUTO, equinox
**                              PMRUN_EQUINOX_FILE
**  Notes:
**  1) Does nothing if opt is NULL.
*/
void pmrun_options_default(pmrun_options *opt);

/*
**  pmrun_read - read a pointing run from a file.
**
**  Given:
**     path     const char*           file to read
**     opt      const pmrun_options*  options, NULL for the defaults
**     errlen   size_t                size of err (bytes)
**  Returned:
**     out      pmrun**               the run (free with pmrun_free); NULL
**                                    on error
**     err      char*                 on error "path:LINE: what was wrong,
**                                    what was expected" (NUL-terminated,
**                                    truncated to errlen); may be NULL
**  Returned (function value):
**              int                   PMRUN_OK; PMRUN_ERR_ARG, _IO,
**                                    _FORMAT, _NOMEM
**  Notes:
**  1) *out is set to NULL on entry and only set on success: nothing is
**     returned half-way.
**  2) The format is detected from the content (docs/formats.md,
**     "Detection") unless opt->format names one.  An error of a reader
**     chosen by detection or by opt->format says which format it read the
**     file as ("path:LINE: read as an RTS2 gpoint input file (...): ...").
**  3) Notes that do not stop the reading (unknown TPOINT options,
**     implausible weather, skipped records ...) come back as warnings:
**     pmrun_n_warnings / pmrun_warning.
**  4) Lines are at most PMRUN_MAX_LINE bytes and files at most
**     PMRUN_MAX_RECORDS records; longer lines are an error
**     ("line too long"), never read into memory unbounded.
*/
int pmrun_read(const char *path, const pmrun_options *opt, pmrun **out,
               char *err, size_t errlen);

/*
**  pmrun_free - release a run and all it owns.  NULL is allowed.
*/
void pmrun_free(pmrun *run);

/*
**  pmrun_count - number of observations (0 for NULL).
*/
size_t pmrun_count(const pmrun *run);

/*
**  pmrun_get - observation i (0-based), NULL if i >= pmrun_count or run is
**  NULL.  The pointer stays valid until pmrun_free.
*/
const pmrun_obs *pmrun_get(const pmrun *run, size_t i);

/*
**  pmrun_mount - PMRUN_MOUNT_EQUATORIAL or PMRUN_MOUNT_ALTAZ (-1 for NULL).
*/
int pmrun_mount(const pmrun *run);

/*
**  pmrun_format - PMRUN_FORMAT_FOUR_COLUMN, _NAMED, _TPOINT, _RTS2, _MW4,
**  _CSV or _MMT (-1 for NULL).
*/
int pmrun_format(const pmrun *run);

/*
**  pmrun_format_name - the short name of a format id ("four-column",
**  "named", "tpoint", "rts2", "mw4", "csv", "mmt"; "auto" for
**  PMRUN_FORMAT_AUTO), NULL for any other value.
**
**  pmrun_format_from_name - the id of a short name (case-insensitive; also
**  "auto"), -2 if the name is not one of them or NULL.
*/
const char *pmrun_format_name(int format);
int pmrun_format_from_name(const char *name);

/*
**  pmrun_latitude_rad - site latitude (radians), NaN if the file gives
**  none (or run is NULL).
*/
double pmrun_latitude_rad(const pmrun *run);

/*
**  pmrun_get_site - the run's site and weather (see pmrun_site).
**
**  Returned:
**     site     pmrun_site*   filled in
**  Returned (function value):
**              int           PMRUN_OK; PMRUN_ERR_ARG (NULL argument,
**                            site left unchanged)
*/
int pmrun_get_site(const pmrun *run, pmrun_site *site);

/*
**  pmrun_n_aux / pmrun_aux_name - number and names of the auxiliary
**  columns (pmrun_obs.aux[i]); pmrun_aux_name returns NULL if i is out of
**  range.  TPOINT records with fields beyond the standard ones give aux1,
**  aux2 ...
*/
int pmrun_n_aux(const pmrun *run);
const char *pmrun_aux_name(const pmrun *run, int i);

/*
**  pmrun_n_warnings / pmrun_warning - the notes made while reading, each
**  "path:LINE: note" (or "path: note"), in file order; at most
**  PMRUN_MAX_MESSAGES are kept, then one saying how many more there were.
**  pmrun_warning returns NULL if i is out of range.
*/
int pmrun_n_warnings(const pmrun *run);
const char *pmrun_warning(const pmrun *run, int i);

/*
**  pmrun_n_skipped / pmrun_skipped - the records skipped with
**  options.skip_bad: the count of all skipped records, and the message of
**  skipped record i ("path:LINE: skipped: why"), NULL if i is out of range
**  or beyond the PMRUN_MAX_MESSAGES kept.  Each one is also in the
**  warnings.
*/
int pmrun_n_skipped(const pmrun *run);
const char *pmrun_skipped(const pmrun *run, int i);

#ifdef __cplusplus
}
#endif

#endif /* PMRUN_RUNFILE_H */
