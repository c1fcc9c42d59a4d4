//! `yat luxconsole [luxconsole's options] scene.lxs|-`: LuxRender 1.x's `luxconsole` command
//! line, read as luxconsole reads it and run as `yat render`, so that LuxBlend's external
//! renderer and pipe paths and scripts written for luxconsole run YAT unchanged. The `yat`
//! binary started under the name `luxconsole` (a link or a copy) reads its command line so too.
//!
//! ```text
//! luxconsole -t 4 -u node1 -u node2:7878 -o /renders/frame.png scene.lxs
//! luxconsole - -b -u node1 -i 180 --threads=4 < scene.lxs > pixels.rgb
//! ```
//!
//! The syntax is boost::program_options' as luxconsole 1.x sets it up (`-t 2`, `-t2`,
//! `--threads 2`, `--threads=2`, switches grouped as `-qf`, `--` before file names, long names
//! never abbreviated). Every luxconsole option is in [`OPTIONS`], with what YAT does with it:
//! mapped onto `yat render`'s flags, ignored with a warning that names it and says why, or
//! refused with an error that does; an option luxconsole does not have is an error naming it.
//! The mapping writes `yat render` flags and parses them as `yat render` does
//! ([`Plan::render_args`]), so every default is `yat render`'s, and the render is
//! [`render::run`].
//!
//! Where files go, as luxconsole puts them: luxconsole changes into a scene file's folder before
//! it renders it, so the Film's filename and a relative `-o` land beside the scene; so does
//! this. LuxRender's `-o NAME` is a base name (it drops NAME's extension and each film output
//! adds its own); so is YAT's: it passes NAME with its extension replaced by `.png` to
//! `yat render -o`, which writes the Film's PNG there and its TGA and EXR beside it. A scene on
//! standard input (`-`) is read as luxconsole reads it, against the current folder: its bytes
//! (at most [`MAX_STDIN_BYTES`]) are staged in a private temporary file created there (mode
//! 0600, removed after its render), so its relative Includes and textures resolve there, and
//! its image is written there. Several scenes render one after another, each to its own
//! Film's filename; `-o` with more than one is refused (every render would overwrite it).

use std::ffi::{OsStr, OsString};
use std::fs::File;
use std::io::{Read, Write};
use std::net::{IpAddr, SocketAddr};
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Parser;
use tempfile::NamedTempFile;

use super::render::{self, RenderArgs};
// A `-u HOST` without a port gets `yat worker`'s default (a LuxRender slave's, 18018, is no
// YAT worker's).
use super::worker::DEFAULT_PORT as WORKER_PORT;
use crate::frames::read_list_file;
use crate::isa::{self, IsaChoice};

/// The name under which the `yat` binary reads luxconsole's command line.
pub const LUXCONSOLE: &str = "luxconsole";

/// The most bytes of a scene read from standard input: what a scene may parse at most under
/// the default build budget.
pub const MAX_STDIN_BYTES: u64 = yat_tracer::budget::DEFAULT_MAX_PARSED_BYTES;

/// The file luxconsole reads options from when it is in the current folder (`-C` names
/// another); YAT does not read it.
const CONFIG_FILE: &str = "luxconsole.cfg";

#[derive(clap::Args, Debug)]
pub struct LuxconsoleArgs {
    /// luxconsole 1.x's options and the scene files (`-` for standard input); `yat luxconsole
    /// --help` lists every luxconsole option and what YAT does with it.
    #[arg(
        num_args = 0..,
        allow_hyphen_values = true,
        trailing_var_arg = true,
        value_name = "LUXCONSOLE ARGS"
    )]
    pub args: Vec<OsString>,
}

impl LuxconsoleArgs {
    /// The log filter the verbosity options ask for (`yat render`'s when they do not parse:
    /// the error is [`run`]'s to report).
    pub fn log_filter(&self) -> &'static str {
        Options::parse(self.args.iter().cloned())
            .map_or(Verbosity::Default, |o| o.verbosity)
            .log_filter()
    }
}

/// Whether a program started as `argv0` is luxconsole (`luxconsole`, `/opt/lux/luxconsole`,
/// `luxconsole.exe`).
pub fn is_luxconsole_name(argv0: &OsStr) -> bool {
    Path::new(argv0).file_stem() == Some(OsStr::new(LUXCONSOLE))
}

/// [`isa::start`] for a process started under the name `luxconsole`: the x86-64-v3 build it
/// hands over to reads its first argument as a subcommand, so it is handed `luxconsole` and
/// then the options (a link named luxconsole resolves to the `yat` beside that build).
pub fn start_isa() -> Result<(), String> {
    let Some((_, IsaChoice::HandOver(sibling))) = isa::this_process() else {
        // Staying, handing back, or this build cannot run here: isa::start decides.
        return isa::start();
    };
    isa::exec(&sibling, isa::V3_NAME, Some(LUXCONSOLE));
    Ok(())
}

/// What an option takes after it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Value {
    Switch,
    Text,
    Unsigned,
    Float,
}

/// What YAT does with a luxconsole option.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Effect {
    Help,
    Version,
    Output,
    FixedSeed,
    ListFile,
    Bindump,
    UseServer,
    Verbose,
    Quiet,
    VeryQuiet,
    LogConsole,
    Threads,
    InputFile,
    /// Accepted, with a warning that names the option and gives this reason.
    Ignored(&'static str),
    /// An error that names the option and gives this reason.
    Refused(&'static str),
}

/// One luxconsole 1.x option: its names, its value, whether it may be given more than once,
/// and what YAT does with it (`yat`: the mapping, as `--help` prints it).
pub struct LuxOption {
    pub long: &'static str,
    pub short: Option<char>,
    value: Value,
    repeatable: bool,
    effect: Effect,
    yat: &'static str,
}

impl LuxOption {
    /// `--output (-o)`, as messages name it.
    pub fn name(&self) -> String {
        match self.short {
            Some(c) => format!("--{} (-{c})", self.long),
            None => format!("--{}", self.long),
        }
    }
}

const fn option(
    long: &'static str,
    short: Option<char>,
    value: Value,
    effect: Effect,
    yat: &'static str,
) -> LuxOption {
    LuxOption {
        long,
        short,
        value,
        repeatable: false,
        effect,
        yat,
    }
}

const fn repeatable(option: LuxOption) -> LuxOption {
    LuxOption {
        repeatable: true,
        ..option
    }
}

/// luxconsole's hidden option that its bare names are (scene files).
const INPUT_FILE: LuxOption = repeatable(option(
    "input-file",
    None,
    Value::Text,
    Effect::InputFile,
    "a scene file, as a name given without an option",
));

const SERVER_MODE_ONLY: &str =
    "it belongs to server mode (-s), which YAT does not run; luxconsole too ignores it without -s";
const EPSILON: &str = "YAT offsets its rays by its own rule, which no option changes";

/// Every option of luxconsole 1.x (its generic, standalone, master, slave, configuration and
/// hidden options), in its order.
pub const OPTIONS: &[LuxOption] = &[
    option(
        "version",
        Some('v'),
        Value::Switch,
        Effect::Version,
        "prints YAT's version",
    ),
    option(
        "help",
        Some('h'),
        Value::Switch,
        Effect::Help,
        "prints this list",
    ),
    option(
        "resume",
        Some('r'),
        Value::Switch,
        Effect::Ignored(
            "YAT saves every render to <output>.resume as it goes and resumes from it when the \
             same command runs again; it cannot read LuxRender's .flm films",
        ),
        "",
    ),
    option(
        "overrideresume",
        Some('R'),
        Value::Text,
        Effect::Refused(
            "YAT cannot read LuxRender's .flm films; it resumes a render from its own \
             checkpoint beside the output (<output>.resume) by itself",
        ),
        "",
    ),
    option(
        "output",
        Some('o'),
        Value::Text,
        Effect::Output,
        "-o NAME with NAME's extension replaced by .png (LuxRender's -o is a base name: the \
         Film's TGA and EXR go beside it as NAME.tga, NAME.exr); a relative NAME is in the \
         scene's folder, where luxconsole writes it",
    ),
    option(
        "fixedseed",
        Some('f'),
        Value::Switch,
        Effect::FixedSeed,
        "--seed 0, as without it: YAT is deterministic, so every render of a scene with the \
         same settings is the same image",
    ),
    option(
        "minepsilon",
        Some('e'),
        Value::Float,
        Effect::Ignored(EPSILON),
        "",
    ),
    option(
        "maxepsilon",
        Some('E'),
        Value::Float,
        Effect::Ignored(EPSILON),
        "",
    ),
    repeatable(option(
        "list-file",
        Some('L'),
        Value::Text,
        Effect::ListFile,
        "renders the scenes the file lists, one path a line, after the command line's",
    )),
    option(
        "bindump",
        Some('b'),
        Value::Switch,
        Effect::Bindump,
        "after each render, writes its 8-bit RGB pixels (rows top to bottom, no header) to \
         standard output; YAT's messages for standard output go to standard error",
    ),
    repeatable(option(
        "useserver",
        Some('u'),
        Value::Text,
        Effect::UseServer,
        "--workers HOST:PORT; a HOST without a port gets YAT's worker port, 7878 (the token \
         comes from YAT_TOKEN)",
    )),
    option(
        "serverinterval",
        Some('i'),
        Value::Unsigned,
        Effect::Ignored(
            "YAT's workers send each unit's samples as soon as it is rendered: there is \
             nothing to poll",
        ),
        "",
    ),
    repeatable(option(
        "resetserver",
        None,
        Value::Text,
        Effect::Refused(
            "a YAT worker keeps no film to reset: a render's sessions end with its coordinator",
        ),
        "",
    )),
    option(
        "server",
        Some('s'),
        Value::Switch,
        Effect::Refused(
            "run `yat worker --listen 0.0.0.0:7878` (with a token in YAT_TOKEN) on each render \
             node, and list the nodes with -u",
        ),
        "",
    ),
    option(
        "serverport",
        Some('p'),
        Value::Unsigned,
        Effect::Ignored(SERVER_MODE_ONLY),
        "",
    ),
    option(
        "serverwriteflm",
        Some('W'),
        Value::Switch,
        Effect::Ignored(SERVER_MODE_ONLY),
        "",
    ),
    option(
        "cachedir",
        Some('c'),
        Value::Text,
        Effect::Ignored(SERVER_MODE_ONLY),
        "",
    ),
    option(
        "verbose",
        Some('V'),
        Value::Switch,
        Effect::Verbose,
        "logs YAT's debug messages",
    ),
    option(
        "quiet",
        Some('q'),
        Value::Switch,
        Effect::Quiet,
        "--quiet: no progress and no summary",
    ),
    option(
        "very-quiet",
        Some('x'),
        Value::Switch,
        Effect::VeryQuiet,
        "--quiet, and errors only: no warnings",
    ),
    option(
        "configfile",
        Some('C'),
        Value::Text,
        Effect::Refused(
            "YAT reads luxconsole's options from the command line only: give them there",
        ),
        "",
    ),
    option(
        "logconsole",
        Some('l'),
        Value::Switch,
        Effect::LogConsole,
        "nothing to do: YAT's log is on standard error already",
    ),
    option(
        "debug",
        Some('d'),
        Value::Switch,
        Effect::FixedSeed,
        "as -f (luxconsole's debug mode fixes the seed)",
    ),
    option(
        "threads",
        Some('t'),
        Value::Unsigned,
        Effect::Threads,
        "--threads N (at least 1); with -u the workers render on their own threads",
    ),
    option(
        "password",
        Some('P'),
        Value::Text,
        Effect::Ignored(
            "it is the password of --resetserver and of server mode, which YAT does not run",
        ),
        "",
    ),
    INPUT_FILE,
    option(
        "test",
        None,
        Value::Switch,
        Effect::Ignored("luxconsole 1.x does nothing with it either"),
        "",
    ),
];

/// A command line that is not luxconsole's, or that asks what YAT does not do.
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum OptionError {
    #[error(
        "unknown luxconsole option{}: {} (`yat luxconsole --help` lists luxconsole's options \
         and what YAT does with each)",
        if .0.len() > 1 { "s" } else { "" },
        .0.join(", ")
    )]
    Unknown(Vec<String>),
    #[error("luxconsole option {0} needs a value")]
    MissingValue(String),
    #[error("luxconsole option {0} takes no value")]
    UnexpectedValue(String),
    #[error("luxconsole option {0} is given more than once (luxconsole takes it once)")]
    Twice(String),
    #[error("luxconsole option {option}: {value:?} {problem}")]
    BadValue {
        option: String,
        value: String,
        problem: &'static str,
    },
    #[error("{}", refusals(.0))]
    Refused(Vec<(String, &'static str)>),
}

/// One line for each option refused: its name and why.
fn refusals(refused: &[(String, &'static str)]) -> String {
    let lines: Vec<String> = refused
        .iter()
        .map(|(option, why)| format!("luxconsole option {option} is not supported by YAT: {why}"))
        .collect();
    lines.join("\n")
}

/// How much luxconsole says: its -V, -q and -x (the quietest given wins, as in luxconsole).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub enum Verbosity {
    Verbose,
    #[default]
    Default,
    Quiet,
    VeryQuiet,
}

impl Verbosity {
    /// The log filter (`YAT_LOG` still wins).
    pub fn log_filter(self) -> &'static str {
        match self {
            Self::Verbose => "info,yat=debug,yat_worker=debug,yat_proto=debug,yat_tracer=debug",
            Self::Default | Self::Quiet => "warn",
            Self::VeryQuiet => "error",
        }
    }
}

/// A luxconsole command line, as given.
#[derive(Debug, Default, PartialEq)]
pub struct Options {
    pub help: bool,
    pub version: bool,
    /// The scene files named on the command line (bare or with --input-file), in order; `-`
    /// is standard input.
    pub scenes: Vec<OsString>,
    pub list_files: Vec<PathBuf>,
    pub output: Option<OsString>,
    pub threads: Option<u32>,
    pub servers: Vec<String>,
    /// -f or -d.
    pub fixed_seed: bool,
    pub verbosity: Verbosity,
    pub bindump: bool,
    /// Options accepted with no effect: (name, why).
    pub ignored: Vec<(String, &'static str)>,
    /// Options YAT does not run: (name, why).
    pub refused: Vec<(String, &'static str)>,
}

impl Options {
    /// Reads luxconsole's command line (without the program's name).
    pub fn parse(args: impl IntoIterator<Item = OsString>) -> Result<Self, OptionError> {
        // The options given and the scene names, in their order.
        let mut given: Vec<(&'static LuxOption, Option<OsString>)> = Vec::new();
        let mut unknown = Vec::new();
        let mut args = args.into_iter();
        let mut files_only = false;
        while let Some(arg) = args.next() {
            let bytes = arg.as_bytes();
            if files_only || bytes == b"-" || !bytes.starts_with(b"-") {
                given.push((&INPUT_FILE, Some(arg)));
            } else if bytes == b"--" {
                files_only = true;
            } else if let Some(long) = bytes.strip_prefix(b"--") {
                let (name, inline) = match long.iter().position(|&b| b == b'=') {
                    Some(i) => (&long[..i], Some(OsString::from_vec(long[i + 1..].to_vec()))),
                    None => (long, None),
                };
                let Some(option) = OPTIONS.iter().find(|o| o.long.as_bytes() == name) else {
                    unknown.push(format!("--{}", String::from_utf8_lossy(name)));
                    continue;
                };
                let value = match (option.value, inline) {
                    (Value::Switch, Some(_)) => {
                        return Err(OptionError::UnexpectedValue(option.name()))
                    }
                    (Value::Switch, None) => None,
                    (_, Some(value)) => Some(value),
                    (_, None) => Some(
                        args.next()
                            .ok_or_else(|| OptionError::MissingValue(option.name()))?,
                    ),
                };
                given.push((option, value));
            } else {
                // Short options, grouped: switches, then at most one that takes the rest of
                // the argument (or the next one) as its value.
                let group = &bytes[1..];
                for (i, &byte) in group.iter().enumerate() {
                    let Some(option) = OPTIONS
                        .iter()
                        .find(|o| byte.is_ascii() && o.short == Some(char::from(byte)))
                    else {
                        unknown.push(if byte.is_ascii() {
                            format!("-{}", char::from(byte))
                        } else {
                            arg.to_string_lossy().into_owned()
                        });
                        if byte.is_ascii() {
                            continue;
                        }
                        break;
                    };
                    if option.value == Value::Switch {
                        given.push((option, None));
                        continue;
                    }
                    let rest = &group[i + 1..];
                    let value = if rest.is_empty() {
                        args.next()
                            .ok_or_else(|| OptionError::MissingValue(option.name()))?
                    } else {
                        OsString::from_vec(rest.to_vec())
                    };
                    given.push((option, Some(value)));
                    break;
                }
            }
        }
        if !unknown.is_empty() {
            return Err(OptionError::Unknown(unknown));
        }
        let mut options = Self::default();
        let mut seen: Vec<&str> = Vec::new();
        for (option, value) in given {
            if value.is_some() && !option.repeatable {
                if seen.contains(&option.long) {
                    return Err(OptionError::Twice(option.name()));
                }
                seen.push(option.long);
            }
            options.take(option, value)?;
        }
        Ok(options)
    }

    /// Records one option given.
    fn take(&mut self, option: &LuxOption, value: Option<OsString>) -> Result<(), OptionError> {
        let bad = |value: &OsStr, problem| OptionError::BadValue {
            option: option.name(),
            value: value.to_string_lossy().into_owned(),
            problem,
        };
        let text = |value: &OsString| {
            value
                .to_str()
                .map(str::to_string)
                .ok_or_else(|| bad(value, "is not UTF-8 text"))
        };
        let number = match (option.value, &value) {
            (Value::Unsigned, Some(v)) => Some(
                text(v)?
                    .parse::<u32>()
                    .map_err(|_| bad(v, "is not a whole number (0 to 4294967295)"))?,
            ),
            (Value::Float, Some(v)) => {
                text(v)?
                    .parse::<f32>()
                    .map_err(|_| bad(v, "is not a number"))?;
                None
            }
            _ => None,
        };
        match option.effect {
            Effect::Help => self.help = true,
            Effect::Version => self.version = true,
            Effect::Output => self.output = value,
            Effect::FixedSeed => self.fixed_seed = true,
            Effect::ListFile => self.list_files.extend(value.map(PathBuf::from)),
            Effect::Bindump => self.bindump = true,
            Effect::UseServer => {
                if let Some(v) = &value {
                    self.servers.push(text(v)?);
                }
            }
            Effect::Verbose => {
                if self.verbosity < Verbosity::Quiet {
                    self.verbosity = Verbosity::Verbose;
                }
            }
            Effect::Quiet => self.verbosity = self.verbosity.max(Verbosity::Quiet),
            Effect::VeryQuiet => self.verbosity = Verbosity::VeryQuiet,
            Effect::LogConsole => {}
            Effect::Threads => {
                let n = number.unwrap_or(0);
                if n == 0 {
                    return Err(bad(
                        value.as_deref().unwrap_or_default(),
                        "is no number of threads: give at least 1",
                    ));
                }
                self.threads = Some(n);
            }
            Effect::InputFile => self.scenes.extend(value),
            Effect::Ignored(why) => self.ignored.push((option.name(), why)),
            Effect::Refused(why) => self.refused.push((option.name(), why)),
        }
        Ok(())
    }
}

/// Where a scene comes from.
#[derive(Debug, PartialEq, Eq)]
pub enum SceneInput {
    /// A scene file, by its absolute path.
    File(PathBuf),
    /// `-`: the scene on standard input.
    Stdin,
}

/// The renders a luxconsole command line asks for, as `yat render` runs them.
#[derive(Debug)]
pub struct Plan {
    /// Rendered in this order.
    pub scenes: Vec<SceneInput>,
    /// `-o` as YAT writes it (a `.png`), relative to the scene's folder unless absolute.
    pub output: Option<PathBuf>,
    pub threads: Option<u32>,
    /// `--workers` entries.
    pub workers: Vec<String>,
    pub verbosity: Verbosity,
    pub bindump: bool,
    /// Said before rendering (unless -x): the options ignored, and why.
    pub warnings: Vec<String>,
}

impl Plan {
    /// The renders `options` ask for, with relative paths (scenes, list files, their lines)
    /// taken from `cwd`; refuses what YAT does not do, each option by name, and a missing
    /// scene file or `-o` folder before anything renders.
    pub fn new(options: Options, cwd: &Path) -> anyhow::Result<Self> {
        if !options.refused.is_empty() {
            return Err(OptionError::Refused(options.refused).into());
        }
        let mut names = options.scenes.clone();
        for list in &options.list_files {
            let listed =
                read_list_file(&cwd.join(list)).map_err(|e| anyhow::anyhow!("{e:#} (-L)"))?;
            names.extend(listed);
        }
        if names.is_empty() {
            anyhow::bail!(
                "no scene given: yat luxconsole [luxconsole options] scene.lxs|- \
                 (`yat luxconsole --help` lists the options)"
            );
        }
        let scenes: Vec<SceneInput> = names
            .iter()
            .map(|name| match name.as_bytes() {
                b"-" => SceneInput::Stdin,
                _ => SceneInput::File(cwd.join(name)),
            })
            .collect();
        if scenes.iter().filter(|s| **s == SceneInput::Stdin).count() > 1 {
            anyhow::bail!("standard input holds one scene: `-` is given more than once");
        }
        let missing: Vec<String> = scenes
            .iter()
            .filter_map(|scene| match scene {
                SceneInput::File(path) if !path.is_file() => Some(path.display().to_string()),
                _ => None,
            })
            .collect();
        if !missing.is_empty() {
            anyhow::bail!("cannot find scene file {}", missing.join(", "));
        }
        let output = options
            .output
            .as_deref()
            .map(|name| output_png(name, &scenes, cwd))
            .transpose()?;
        let workers = options
            .servers
            .iter()
            .map(|server| worker_address(server))
            .collect::<Result<Vec<_>, _>>()?;
        let mut warnings: Vec<String> = options
            .ignored
            .iter()
            .map(|(option, why)| format!("luxconsole option {option} is ignored by YAT: {why}"))
            .collect();
        let mut threads = options.threads;
        if threads.is_some() && !workers.is_empty() {
            threads = None;
            warnings.push(
                "luxconsole option --threads (-t) is ignored with --useserver (-u): YAT's \
                 workers render on their own threads and this machine coordinates (start a \
                 `yat worker` here too and list it with -u to render on it)"
                    .into(),
            );
        }
        if cwd.join(CONFIG_FILE).exists() {
            warnings.push(format!(
                "{} is not read: YAT takes luxconsole's options from the command line only",
                cwd.join(CONFIG_FILE).display()
            ));
        }
        Ok(Self {
            scenes,
            output,
            threads,
            workers,
            verbosity: options.verbosity,
            bindump: options.bindump,
            warnings,
        })
    }

    /// The `yat render` flags of the render of the scene file at `scene`.
    pub fn render_argv(&self, scene: &Path) -> Vec<OsString> {
        let mut argv: Vec<OsString> = vec!["yat render".into(), scene.into()];
        // The sampler's seed, with or without -f: YAT's renders are deterministic.
        argv.extend(["--seed".into(), "0".into()]);
        if let Some(threads) = self.threads {
            argv.extend(["--threads".into(), threads.to_string().into()]);
        }
        if let Some(output) = &self.output {
            argv.extend(["--output".into(), output.into()]);
        }
        for worker in &self.workers {
            argv.extend(["--workers".into(), worker.into()]);
        }
        if self.verbosity >= Verbosity::Quiet {
            argv.push("--quiet".into());
        }
        argv
    }

    /// [`Self::render_argv`] read as `yat render` reads it.
    pub fn render_args(&self, scene: &Path) -> anyhow::Result<RenderArgs> {
        RenderCommand::try_parse_from(self.render_argv(scene))
            .map(|command| command.render)
            .map_err(|e| anyhow::anyhow!("the render luxconsole's options ask for: {e}"))
    }
}

/// `yat render`'s flags alone.
#[derive(Parser)]
struct RenderCommand {
    #[command(flatten)]
    render: RenderArgs,
}

/// `-o NAME` as YAT writes it: NAME with its extension replaced by `.png`, checked to be a file
/// in a folder that exists (relative to the scene's folder, or the current one for `-`); one
/// scene only.
fn output_png(name: &OsStr, scenes: &[SceneInput], cwd: &Path) -> anyhow::Result<PathBuf> {
    let option = "luxconsole option --output (-o)";
    if scenes.len() > 1 {
        anyhow::bail!(
            "{option} names one image, and {} scenes would each overwrite it: leave it out to \
             write each scene's image under its Film's filename beside the scene",
            scenes.len()
        );
    }
    let path = Path::new(name);
    let Some(stem) = path
        .file_stem()
        .filter(|_| !name.as_bytes().ends_with(b"/"))
    else {
        anyhow::bail!("{option} {:?} names no file", name.to_string_lossy());
    };
    let mut file = stem.to_os_string();
    file.push(".png");
    let png = path.with_file_name(file);
    let base = match scenes.first() {
        Some(SceneInput::File(scene)) => scene.parent().unwrap_or(cwd),
        _ => cwd,
    };
    let folder = base.join(&png);
    let folder = folder.parent().unwrap_or(base);
    if !folder.is_dir() {
        anyhow::bail!(
            "{option} {:?}: the folder {} does not exist (a relative name is in the scene's \
             folder, as luxconsole writes it)",
            name.to_string_lossy(),
            folder.display()
        );
    }
    Ok(png)
}

/// `-u SERVER` as a `--workers` entry: HOST:PORT, IP:PORT and [IPv6]:PORT as given; a host or
/// an IP address without a port gets [`WORKER_PORT`].
fn worker_address(server: &str) -> Result<String, OptionError> {
    let bad = |problem| OptionError::BadValue {
        option: "--useserver (-u)".into(),
        value: server.into(),
        problem,
    };
    if server.is_empty() || server.contains(|c: char| c == ',' || c.is_whitespace()) {
        return Err(bad("is not one host or host:port"));
    }
    if server.parse::<SocketAddr>().is_ok() {
        return Ok(server.into());
    }
    let bare = server
        .strip_prefix('[')
        .and_then(|s| s.strip_suffix(']'))
        .unwrap_or(server);
    if let Ok(ip) = bare.parse::<IpAddr>() {
        return Ok(SocketAddr::new(ip, WORKER_PORT).to_string());
    }
    match server.rsplit_once(':') {
        None => Ok(format!("{server}:{WORKER_PORT}")),
        Some((host, port))
            if !host.is_empty()
                && !host.contains([':', '[', ']'])
                && port.parse::<u16>().is_ok_and(|p| p != 0) =>
        {
            Ok(server.into())
        }
        Some(_) => Err(bad(
            "is not HOST, HOST:PORT (a port from 1 to 65535), an IP address or [IPv6]:PORT",
        )),
    }
}

/// Stages at most `limit` bytes of `input` in a private temporary file in `dir` (removed when
/// dropped), as the scene's main file: its relative Includes and textures resolve in `dir`.
pub fn stage_scene(input: impl Read, dir: &Path, limit: u64) -> anyhow::Result<NamedTempFile> {
    let mut file = tempfile::Builder::new()
        .prefix(".yat-stdin-")
        .suffix(".lxs")
        .tempfile_in(dir)
        .with_context(|| {
            format!(
                "cannot stage the scene from standard input in {} (its Includes and textures \
                 are read from there, as luxconsole reads them)",
                dir.display()
            )
        })?;
    let copied = std::io::copy(&mut input.take(limit + 1), file.as_file_mut())
        .context("cannot read the scene from standard input")?;
    if copied > limit {
        anyhow::bail!(
            "the scene on standard input is larger than {} MiB, the most YAT reads there: write \
             it to a file and give its path",
            limit >> 20
        );
    }
    Ok(file)
}

/// Points standard output at standard error, for everything YAT prints, and returns the
/// original standard output, for -b's pixels alone.
fn keep_stdout_for_pixels() -> anyhow::Result<File> {
    use std::os::fd::AsFd;
    std::io::stdout().flush()?;
    let pixels = std::io::stdout()
        .as_fd()
        .try_clone_to_owned()
        .context("cannot keep standard output for the pixels (-b)")?;
    // SAFETY: dup2 of two descriptors this process has open only changes what descriptor 1
    // refers to; Rust's standard output holds no other state about it (flushed above).
    if unsafe { libc::dup2(libc::STDERR_FILENO, libc::STDOUT_FILENO) } < 0 {
        return Err(std::io::Error::last_os_error())
            .context("cannot send YAT's messages to standard error (-b)");
    }
    Ok(File::from(pixels))
}

/// -b: the PNG just written, as 8-bit RGB, rows top to bottom.
fn dump_pixels(out: &mut File, png: &Path) -> anyhow::Result<()> {
    let image = image::open(png)
        .with_context(|| format!("cannot read back {} (-b)", png.display()))?
        .to_rgb8();
    out.write_all(image.as_raw())
        .and_then(|()| out.flush())
        .context("cannot write the pixels to standard output (-b)")
}

/// `yat luxconsole --help`: the usage and every luxconsole option with what YAT does with it.
pub fn help() -> String {
    let mut text = String::from(
        "Usage: yat luxconsole [luxconsole options] scene.lxs|- ...\n       \
         luxconsole [luxconsole options] scene.lxs|- ...   (yat under the name luxconsole)\n\n\
         LuxRender 1.x's luxconsole command line, rendered as `yat render` renders. A \
         relative -o and the Film's filename are in the scene's folder; `-` reads the scene \
         from standard input, against the current folder.\n\nluxconsole's options and what \
         YAT does with each:\n",
    );
    for option in OPTIONS {
        let value = match option.value {
            Value::Switch => "",
            Value::Text => " TEXT",
            Value::Unsigned => " N",
            Value::Float => " X",
        };
        let names = match option.short {
            Some(c) => format!("-{c}, --{}{value}", option.long),
            None => format!("    --{}{value}", option.long),
        };
        let what = match option.effect {
            Effect::Ignored(why) => format!("ignored: {why}"),
            Effect::Refused(why) => format!("refused: {why}"),
            _ => option.yat.to_string(),
        };
        text.push_str(&format!("  {names:<26} {what}\n"));
    }
    text
}

/// Runs luxconsole's command line: each scene rendered by `yat render` in turn, the first
/// error ending the queue.
pub fn run(args: LuxconsoleArgs) -> anyhow::Result<()> {
    let options = Options::parse(args.args)?;
    if options.help {
        print!("{}", help());
        return Ok(());
    }
    if options.version {
        println!(
            "yat {} (renderer build {}), reading luxconsole 1.x's command line",
            env!("CARGO_PKG_VERSION"),
            yat_tracer::RENDERER_BUILD
        );
        return Ok(());
    }
    let cwd = std::env::current_dir().context("cannot read the current folder")?;
    let plan = Plan::new(options, &cwd)?;
    if plan.verbosity < Verbosity::VeryQuiet {
        for warning in &plan.warnings {
            eprintln!("warning: {warning}");
        }
    }
    let mut pixels = plan.bindump.then(keep_stdout_for_pixels).transpose()?;
    let count = plan.scenes.len();
    for (i, scene) in plan.scenes.iter().enumerate() {
        // As luxconsole: a scene file renders in its folder, standard input's in the current.
        let (path, _staged) = match scene {
            SceneInput::File(path) => {
                let folder = path.parent().unwrap_or(&cwd);
                std::env::set_current_dir(folder)
                    .with_context(|| format!("cannot change into {}", folder.display()))?;
                (path.clone(), None)
            }
            SceneInput::Stdin => {
                std::env::set_current_dir(&cwd)
                    .with_context(|| format!("cannot change into {}", cwd.display()))?;
                let staged = stage_scene(std::io::stdin().lock(), &cwd, MAX_STDIN_BYTES)?;
                (staged.path().to_path_buf(), Some(staged))
            }
        };
        let png = render::run(plan.render_args(&path)?).with_context(|| match scene {
            SceneInput::Stdin => "cannot render the scene read from standard input".to_string(),
            SceneInput::File(path) => {
                format!(
                    "cannot render scene {} of {count}, {}",
                    i + 1,
                    path.display()
                )
            }
        })?;
        if let Some(out) = &mut pixels {
            let Some(png) = png else {
                anyhow::bail!(
                    "-b sends the pixels of the PNG a render writes, and the scene's Film writes \
                     none (write_png false)"
                );
            };
            dump_pixels(out, &png)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(args: &[&str]) -> Result<Options, OptionError> {
        Options::parse(args.iter().map(OsString::from))
    }

    /// A folder with scene files `a.lxs` and `b.lxs` (empty: nothing here parses them).
    fn scenes() -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        for name in ["a.lxs", "b.lxs"] {
            std::fs::write(dir.path().join(name), "").unwrap();
        }
        dir
    }

    fn plan(args: &[&str], cwd: &Path) -> anyhow::Result<Plan> {
        Plan::new(parse(args)?, cwd)
    }

    /// The `yat render` arguments of the first scene of `args` run in `cwd`.
    fn render_args(args: &[&str], cwd: &Path) -> RenderArgs {
        let plan = plan(args, cwd).unwrap();
        let scene = match &plan.scenes[0] {
            SceneInput::File(path) => path.clone(),
            SceneInput::Stdin => cwd.join("staged.lxs"),
        };
        plan.render_args(&scene).unwrap()
    }

    #[test]
    fn every_spelling_of_threads_is_render_threads() {
        let dir = scenes();
        for args in [
            &["-t", "2", "a.lxs"][..],
            &["-t2", "a.lxs"],
            &["--threads", "2", "a.lxs"],
            &["--threads=2", "a.lxs"],
            &["a.lxs", "-t", "2"],
        ] {
            let render = render_args(args, dir.path());
            assert_eq!(render.threads, Some(2), "{args:?}");
            assert_eq!(render.scenes, [dir.path().join("a.lxs")], "{args:?}");
        }
        assert_eq!(render_args(&["a.lxs"], dir.path()).threads, None);
    }

    #[test]
    fn no_thread_is_refused() {
        let error = parse(&["-t", "0", "a.lxs"]).unwrap_err();
        assert!(error.to_string().contains("--threads (-t)"), "{error}");
        assert!(matches!(
            parse(&["-t", "many"]),
            Err(OptionError::BadValue { .. })
        ));
    }

    #[test]
    fn output_is_a_base_name_written_as_png() {
        let dir = scenes();
        std::fs::create_dir(dir.path().join("out")).unwrap();
        for (given, written) in [
            ("frame.png", "frame.png"),
            ("frame.exr", "frame.png"),
            ("frame", "frame.png"),
            ("out/frame.0001.tga", "out/frame.0001.png"),
        ] {
            let render = render_args(&["-o", given, "a.lxs"], dir.path());
            assert_eq!(render.output, Some(PathBuf::from(written)), "{given}");
        }
        let absolute = dir.path().join("out/x.flm");
        let render = render_args(&["-o", absolute.to_str().unwrap(), "a.lxs"], dir.path());
        assert_eq!(render.output, Some(dir.path().join("out/x.png")));
        assert_eq!(render_args(&["a.lxs"], dir.path()).output, None);
    }

    #[test]
    fn output_in_a_missing_folder_or_naming_no_file_is_refused() {
        let dir = scenes();
        for given in ["nowhere/frame.png", "out/", ".."] {
            let error = plan(&["-o", given, "a.lxs"], dir.path()).unwrap_err();
            assert!(
                error.to_string().contains("--output (-o)"),
                "{given}: {error}"
            );
        }
    }

    #[test]
    fn output_with_several_scenes_is_refused() {
        let dir = scenes();
        let error = plan(&["-o", "x.png", "a.lxs", "b.lxs"], dir.path()).unwrap_err();
        assert!(error.to_string().contains("2 scenes"), "{error}");
    }

    #[test]
    fn each_server_is_a_worker_with_yat_s_port_by_default() {
        let dir = scenes();
        let render = render_args(
            &[
                "-u",
                "node1",
                "-u",
                "node2:9000",
                "-u",
                "10.0.0.7",
                "-u",
                "::1",
                "-u",
                "[fe80::2]",
                "-u",
                "[::1]:9001",
                "-u",
                "10.0.0.8:18018",
                "a.lxs",
            ],
            dir.path(),
        );
        assert_eq!(
            render.distributed.workers,
            [
                "node1:7878",
                "node2:9000",
                "10.0.0.7:7878",
                "[::1]:7878",
                "[fe80::2]:7878",
                "[::1]:9001",
                "10.0.0.8:18018"
            ]
        );
        assert!(render_args(&["a.lxs"], dir.path())
            .distributed
            .workers
            .is_empty());
        for bad in [
            "",
            "a,b",
            "node 1",
            "node:0",
            "node:port",
            "[node]:1",
            ":9000",
        ] {
            let error = plan(&["-u", bad, "a.lxs"], dir.path()).unwrap_err();
            assert!(
                error.to_string().contains("--useserver (-u)"),
                "{bad}: {error}"
            );
        }
    }

    #[test]
    fn the_default_port_is_yat_worker_s() {
        #[derive(Parser)]
        struct Worker {
            #[command(flatten)]
            worker: super::super::worker::WorkerArgs,
        }
        let worker = Worker::try_parse_from(["yat worker"]).unwrap();
        assert_eq!(worker.worker.listen.port(), WORKER_PORT);
    }

    #[test]
    fn threads_with_servers_are_the_workers_and_said_so() {
        let dir = scenes();
        let plan = plan(&["-t", "4", "-u", "node1", "a.lxs"], dir.path()).unwrap();
        assert_eq!(plan.threads, None);
        assert!(
            plan.warnings.iter().any(|w| w.contains("--threads (-t)")),
            "{:?}",
            plan.warnings
        );
    }

    #[test]
    fn a_fixed_seed_is_yat_s_seed() {
        let dir = scenes();
        let plain = plan(&["a.lxs"], dir.path()).unwrap();
        let scene = dir.path().join("a.lxs");
        for flag in ["-f", "--fixedseed", "-d", "--debug"] {
            let options = parse(&[flag, "a.lxs"]).unwrap();
            assert!(options.fixed_seed, "{flag}");
            let fixed = Plan::new(options, dir.path()).unwrap();
            assert_eq!(
                fixed.render_argv(&scene),
                plain.render_argv(&scene),
                "{flag}"
            );
            assert_eq!(fixed.render_args(&scene).unwrap().seed, 0, "{flag}");
        }
    }

    #[test]
    fn verbosity_sets_quiet_and_the_log_level() {
        let dir = scenes();
        for (args, quiet, filter) in [
            (&["a.lxs"][..], false, "warn"),
            (&["-V", "a.lxs"], false, Verbosity::Verbose.log_filter()),
            (&["-q", "a.lxs"], true, "warn"),
            (&["--quiet", "a.lxs"], true, "warn"),
            (&["-x", "a.lxs"], true, "error"),
            (&["--very-quiet", "a.lxs"], true, "error"),
            // The quietest given wins, as in luxconsole.
            (&["-q", "-V", "a.lxs"], true, "warn"),
            (&["-xV", "a.lxs"], true, "error"),
        ] {
            assert_eq!(render_args(args, dir.path()).quiet, quiet, "{args:?}");
            let lux = LuxconsoleArgs {
                args: args.iter().map(OsString::from).collect(),
            };
            assert_eq!(lux.log_filter(), filter, "{args:?}");
        }
        assert!(Verbosity::Verbose.log_filter().contains("yat=debug"));
    }

    #[test]
    fn grouped_switches_and_a_value_at_the_end() {
        let options = parse(&["-qfbt3", "a.lxs"]).unwrap();
        assert_eq!(options.verbosity, Verbosity::Quiet);
        assert!(options.fixed_seed && options.bindump);
        assert_eq!(options.threads, Some(3));
        assert_eq!(options.scenes, [OsString::from("a.lxs")]);
    }

    #[test]
    fn dash_is_standard_input_and_double_dash_ends_the_options() {
        let dir = scenes();
        let plan = plan(&["-", "-t", "1"], dir.path()).unwrap();
        assert_eq!(plan.scenes, [SceneInput::Stdin]);
        let options = parse(&["-t", "1", "--", "-t", "a.lxs"]).unwrap();
        assert_eq!(options.scenes, [OsString::from("-t"), "a.lxs".into()]);
        assert_eq!(options.threads, Some(1));
        let error = plan_error(&["-", "a.lxs", "-"], dir.path());
        assert!(error.contains("more than once"), "{error}");
    }

    fn plan_error(args: &[&str], cwd: &Path) -> String {
        plan(args, cwd).unwrap_err().to_string()
    }

    #[test]
    fn unknown_options_are_named() {
        let error = parse(&["--frobnicate", "-z", "-t", "2", "a.lxs"]).unwrap_err();
        assert_eq!(
            error,
            OptionError::Unknown(vec!["--frobnicate".into(), "-z".into()])
        );
        let text = error.to_string();
        assert!(
            text.contains("--frobnicate") && text.contains("-z"),
            "{text}"
        );
        // Long names are never abbreviated (luxconsole turns boost's guessing off).
        assert_eq!(
            parse(&["--thread", "2"]).unwrap_err(),
            OptionError::Unknown(vec!["--thread".into()])
        );
        // yat render's flags are not luxconsole's.
        assert_eq!(
            parse(&["--spp", "4"]).unwrap_err(),
            OptionError::Unknown(vec!["--spp".into()])
        );
        assert!(matches!(
            Options::parse([OsString::from_vec(b"-\xff".to_vec())]),
            Err(OptionError::Unknown(_))
        ));
    }

    #[test]
    fn unsupported_options_are_refused_by_name() {
        let dir = scenes();
        for (args, name) in [
            (&["-s"][..], "--server (-s)"),
            (&["--server"], "--server (-s)"),
            (&["--resetserver", "node1"], "--resetserver"),
            (&["-R", "old.flm", "a.lxs"], "--overrideresume (-R)"),
            (&["-C", "my.cfg", "a.lxs"], "--configfile (-C)"),
        ] {
            let error = plan_error(args, dir.path());
            assert!(
                error.contains(&format!(
                    "luxconsole option {name} is not supported by YAT: "
                )),
                "{args:?}: {error}"
            );
        }
        let error = plan_error(&["-s", "-C", "x.cfg"], dir.path());
        assert!(
            error.contains("--server (-s)") && error.contains("--configfile (-C)"),
            "{error}"
        );
    }

    #[test]
    fn ignored_options_are_named_in_warnings() {
        let dir = scenes();
        for (args, name) in [
            (&["-e", "0.001", "a.lxs"][..], "--minepsilon (-e)"),
            (&["-E", "-1", "a.lxs"], "--maxepsilon (-E)"),
            (&["-i", "180", "a.lxs"], "--serverinterval (-i)"),
            (&["-p", "18018", "a.lxs"], "--serverport (-p)"),
            (&["-W", "a.lxs"], "--serverwriteflm (-W)"),
            (&["-c", "/tmp/cache", "a.lxs"], "--cachedir (-c)"),
            (&["-P", "secret", "a.lxs"], "--password (-P)"),
            (&["-r", "a.lxs"], "--resume (-r)"),
            (&["--test", "a.lxs"], "--test"),
        ] {
            let plan = plan(args, dir.path()).unwrap();
            assert!(
                plan.warnings
                    .iter()
                    .any(|w| w.starts_with(&format!("luxconsole option {name} is ignored"))),
                "{args:?}: {:?}",
                plan.warnings
            );
        }
        assert!(matches!(
            parse(&["-i", "often"]),
            Err(OptionError::BadValue { .. })
        ));
        assert!(matches!(
            parse(&["-e", "tiny"]),
            Err(OptionError::BadValue { .. })
        ));
        // Mapped options say nothing.
        let plan = plan(&["-l", "-f", "-t", "1", "a.lxs"], dir.path()).unwrap();
        assert!(plan.warnings.is_empty(), "{:?}", plan.warnings);
    }

    #[test]
    fn a_config_file_in_the_current_folder_is_named() {
        let dir = scenes();
        std::fs::write(dir.path().join(CONFIG_FILE), "threads=2\n").unwrap();
        let plan = plan(&["a.lxs"], dir.path()).unwrap();
        assert!(
            plan.warnings.iter().any(|w| w.contains(CONFIG_FILE)),
            "{:?}",
            plan.warnings
        );
    }

    #[test]
    fn malformed_command_lines_are_errors() {
        assert_eq!(
            parse(&["a.lxs", "-t"]).unwrap_err(),
            OptionError::MissingValue("--threads (-t)".into())
        );
        assert_eq!(
            parse(&["--output"]).unwrap_err(),
            OptionError::MissingValue("--output (-o)".into())
        );
        assert_eq!(
            parse(&["--quiet=1"]).unwrap_err(),
            OptionError::UnexpectedValue("--quiet (-q)".into())
        );
        assert_eq!(
            parse(&["-o", "a.png", "--output=b.png"]).unwrap_err(),
            OptionError::Twice("--output (-o)".into())
        );
        let dir = scenes();
        assert!(plan_error(&["-t", "2"], dir.path()).contains("no scene given"));
        let error = plan_error(&["a.lxs", "missing.lxs"], dir.path());
        assert!(error.contains("missing.lxs"), "{error}");
    }

    #[test]
    fn list_files_add_their_scenes_after_the_command_line_s() {
        let dir = scenes();
        std::fs::write(dir.path().join("queue.txt"), "a.lxs\r\n\n  \nb.lxs\n").unwrap();
        let plan = plan(&["b.lxs", "-L", "queue.txt"], dir.path()).unwrap();
        let file = |name| SceneInput::File(dir.path().join(name));
        assert_eq!(plan.scenes, [file("b.lxs"), file("a.lxs"), file("b.lxs")]);
        let error = plan_error(&["-L", "nope.txt"], dir.path());
        assert!(error.contains("nope.txt"), "{error}");
    }

    #[test]
    fn input_file_names_a_scene() {
        let options = parse(&["--input-file", "a.lxs", "b.lxs"]).unwrap();
        assert_eq!(options.scenes, [OsString::from("a.lxs"), "b.lxs".into()]);
    }

    #[test]
    fn luxblend_s_pipe_command_line() {
        // LuxBlend 0.1 runs `luxconsole - -b -u SERVER -i 180 --threads=N` and reads the
        // pixels from standard output.
        let dir = scenes();
        let plan = plan(
            &["-", "-b", "-u", "node1", "-i", "180", "--threads=4"],
            dir.path(),
        )
        .unwrap();
        assert_eq!(plan.scenes, [SceneInput::Stdin]);
        assert!(plan.bindump);
        assert_eq!(plan.workers, ["node1:7878"]);
        assert_eq!(plan.warnings.len(), 2, "{:?}", plan.warnings);
    }

    #[test]
    fn help_and_version_need_no_scene() {
        assert!(parse(&["-h"]).unwrap().help);
        assert!(parse(&["--version"]).unwrap().version);
        let help = help();
        for option in OPTIONS {
            assert!(
                help.contains(&format!("--{}", option.long)),
                "{}",
                option.long
            );
        }
    }

    #[test]
    fn the_table_has_each_name_once() {
        for (i, a) in OPTIONS.iter().enumerate() {
            for b in &OPTIONS[i + 1..] {
                assert_ne!(a.long, b.long);
                assert!(a.short.is_none() || a.short != b.short, "{}", a.long);
            }
            let described =
                matches!(a.effect, Effect::Ignored(_) | Effect::Refused(_)) || !a.yat.is_empty();
            assert!(described, "{} says nothing of what YAT does", a.long);
        }
    }

    #[test]
    fn the_program_s_name_is_luxconsole() {
        for name in ["luxconsole", "/opt/lux/luxconsole", "luxconsole.exe"] {
            assert!(is_luxconsole_name(OsStr::new(name)), "{name}");
        }
        for name in ["yat", "/usr/bin/yat", "luxconsole-x86-64-v3", "luxrender"] {
            assert!(!is_luxconsole_name(OsStr::new(name)), "{name}");
        }
    }

    #[test]
    fn standard_input_is_staged_in_the_folder_within_its_limit() {
        let dir = tempfile::tempdir().unwrap();
        let text = b"WorldBegin\nWorldEnd\n";
        let staged = stage_scene(&text[..], dir.path(), 64).unwrap();
        assert_eq!(staged.path().parent(), Some(dir.path()));
        assert_eq!(std::fs::read(staged.path()).unwrap(), text);
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(staged.path())
            .unwrap()
            .permissions()
            .mode();
        assert_eq!(mode & 0o077, 0, "{mode:o}");
        let path = staged.path().to_path_buf();
        drop(staged);
        assert!(!path.exists());

        let error = stage_scene(&[b' '; 65][..], dir.path(), 64).unwrap_err();
        assert!(error.to_string().contains("larger than"), "{error}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        let error = stage_scene(&text[..], &dir.path().join("nowhere"), 64).unwrap_err();
        assert!(error.to_string().contains("cannot stage"), "{error}");
    }
}
