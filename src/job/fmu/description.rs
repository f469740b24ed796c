//! modelDescription.xml of an exported FMU (FMI 2.0 co-simulation), from the variable table.

use super::variables::{Causality, Role, Variable};
use super::FmuModel;

/// Units the variables use (FMI 2.0 `UnitDefinitions`: SI base-unit exponents).
const UNITS: [(&str, &str); 9] = [
    ("K", r#"K="1""#),
    ("W", r#"kg="1" m="2" s="-3""#),
    ("J", r#"kg="1" m="2" s="-2""#),
    ("rad/s", r#"s="-1" rad="1""#),
    ("N.m", r#"kg="1" m="2" s="-2""#),
    ("m/s", r#"m="1" s="-1""#),
    ("m2/s", r#"m="2" s="-1""#),
    ("s", r#"s="1""#),
    ("1", ""),
];

/// XML text with `&`, `<`, `>` and `"` escaped.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A number as XML (shortest round-trip form).
fn num(v: f64) -> String {
    format!("{v:?}")
}

fn scalar(v: &Variable) -> String {
    let (causality, variability, initial) = match (v.causality, v.integer) {
        (Causality::Input, true) => ("input", "discrete", ""),
        (Causality::Input, false) => ("input", "continuous", ""),
        (Causality::Output, _) => ("output", "continuous", ""),
        // Exported model values may change between steps (`instance`); initial temperatures and
        // tolerances only before initialisation.
        (Causality::Parameter, _) if matches!(v.role, Role::Param(_)) => {
            ("parameter", "tunable", r#" initial="exact""#)
        }
        (Causality::Parameter, _) => ("parameter", "fixed", r#" initial="exact""#),
    };
    let start = v
        .start
        .map(|s| {
            let text = if v.integer {
                format!("{}", s as i64)
            } else {
                num(s)
            };
            format!(r#" start="{text}""#)
        })
        .unwrap_or_default();
    let unit = if v.unit.is_empty() {
        String::new()
    } else {
        format!(r#" unit="{}""#, esc(v.unit))
    };
    let ty = if v.integer {
        format!("<Integer{start}/>")
    } else {
        format!("<Real{unit}{start}/>")
    };
    format!(
        "    <ScalarVariable name=\"{}\" valueReference=\"{}\" causality=\"{causality}\" variability=\"{variability}\"{initial} description=\"{}\">\n      {ty}\n    </ScalarVariable>\n",
        esc(&v.name),
        v.vr,
        esc(&v.description)
    )
}

/// The description of `fm` with model identifier `id` and `guid`.
pub fn model_description(fm: &FmuModel, id: &str, guid: &str) -> String {
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x += &format!(
        "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"{}\" guid=\"{}\" description=\"{}\" generationTool=\"geartherm {}\" variableNamingConvention=\"flat\" numberOfEventIndicators=\"0\">\n",
        esc(&fm.model.gearbox.name),
        guid,
        esc(&format!("geartherm gearbox thermal model from {}", fm.payload.file)),
        env!("CARGO_PKG_VERSION"),
    );
    x += &format!(
        "  <CoSimulation modelIdentifier=\"{id}\" canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"true\" maxOutputDerivativeOrder=\"0\" canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"false\" canSerializeFMUstate=\"false\" providesDirectionalDerivative=\"false\"/>\n"
    );
    x += "  <UnitDefinitions>\n";
    for (name, base) in UNITS {
        x += &format!("    <Unit name=\"{}\"><BaseUnit {base}/></Unit>\n", esc(name));
    }
    x += "  </UnitDefinitions>\n";
    x += &format!(
        "  <DefaultExperiment startTime=\"0.0\" stepSize=\"1.0\" tolerance=\"{}\"/>\n",
        num(crate::job::run::DEFAULT_RTOL)
    );
    x += "  <ModelVariables>\n";
    for v in &fm.vars {
        x += &scalar(v);
    }
    x += "  </ModelVariables>\n  <ModelStructure>\n    <Outputs>\n";
    let outputs: Vec<&Variable> = fm
        .vars
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .collect();
    for v in &outputs {
        x += &format!("      <Unknown index=\"{}\"/>\n", v.vr);
    }
    x += "    </Outputs>\n    <InitialUnknowns>\n";
    for v in &outputs {
        x += &format!("      <Unknown index=\"{}\"/>\n", v.vr);
    }
    x += "    </InitialUnknowns>\n  </ModelStructure>\n</fmiModelDescription>\n";
    x
}
