//! The call generator of FMI 2.0: which function comes next, for a well-behaved master
//! that follows the phase of the instance, or at random (FMI 3.0's is
//! [`crate::fmi3_calls`]); the phase as the test follows it, and the weighted pick both
//! generators use.

use rand::Rng;
use rand::rngs::StdRng;
use wheelflat::fmu::Call;

/// The phase of an instance as the test follows it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mirror {
    Instantiated,
    /// FMI 3.0's Configuration Mode.
    Configuration,
    Initialization,
    Stepping,
    Ended,
    Terminated,
    Unknown,
}

/// One of the weighted items `w` (weights not all 0).
pub fn pick<T: Copy>(rng: &mut StdRng, w: &[(T, u32)]) -> T {
    let total: u32 = w.iter().map(|x| x.1).sum();
    let mut x = rng.random_range(0..total);
    for &(c, n) in w {
        if x < n {
            return c;
        }
        x -= n;
    }
    unreachable!()
}

/// A call a well-behaved master would make next (with valid arguments).
pub fn next_valid_call(rng: &mut StdRng, phase: Mirror) -> Call {
    match phase {
        Mirror::Instantiated => pick(
            rng,
            &[
                (Call::SetReal, 2),
                (Call::SetInteger, 1),
                (Call::SetupExperiment, 2),
                (Call::EnterInitializationMode, 5),
            ],
        ),
        Mirror::Initialization => pick(
            rng,
            &[
                (Call::SetReal, 2),
                (Call::GetReal, 2),
                (Call::ExitInitializationMode, 6),
            ],
        ),
        Mirror::Stepping => pick(
            rng,
            &[
                (Call::DoStep, 60),
                (Call::GetReal, 15),
                (Call::SetReal, 10),
                (Call::GetFMUstate, 4),
                (Call::SetFMUstate, 4),
                (Call::SerializeFMUstate, 2),
                (Call::DeSerializeFMUstate, 2),
                (Call::GetRealStatus, 2),
                (Call::Terminate, 1),
            ],
        ),
        Mirror::Ended => pick(
            rng,
            &[
                (Call::GetReal, 3),
                (Call::GetBooleanStatus, 1),
                (Call::DoStep, 1),
                (Call::Terminate, 3),
                (Call::Reset, 3),
            ],
        ),
        Mirror::Terminated => pick(rng, &[(Call::GetReal, 1), (Call::Reset, 4)]),
        Mirror::Configuration | Mirror::Unknown => pick(
            rng,
            &[
                (Call::EnterInitializationMode, 1),
                (Call::ExitInitializationMode, 1),
                (Call::Reset, 1),
            ],
        ),
    }
}

/// The function of a random call, weighted towards the ones that do something.
pub fn pick_call(rng: &mut StdRng) -> Call {
    const W: [(Call, u32); 34] = [
        (Call::GetTypesPlatform, 1),
        (Call::GetVersion, 1),
        (Call::SetDebugLogging, 2),
        (Call::Instantiate, 3),
        (Call::FreeInstance, 2),
        (Call::SetupExperiment, 4),
        (Call::EnterInitializationMode, 6),
        (Call::ExitInitializationMode, 6),
        (Call::Terminate, 3),
        (Call::Reset, 3),
        (Call::GetReal, 12),
        (Call::GetInteger, 3),
        (Call::GetBoolean, 1),
        (Call::GetString, 1),
        (Call::SetReal, 10),
        (Call::SetInteger, 4),
        (Call::SetBoolean, 1),
        (Call::SetString, 1),
        (Call::GetFMUstate, 4),
        (Call::SetFMUstate, 4),
        (Call::FreeFMUstate, 3),
        (Call::SerializedFMUstateSize, 2),
        (Call::SerializeFMUstate, 3),
        (Call::DeSerializeFMUstate, 3),
        (Call::GetDirectionalDerivative, 1),
        (Call::SetRealInputDerivatives, 1),
        (Call::GetRealOutputDerivatives, 1),
        (Call::DoStep, 18),
        (Call::CancelStep, 1),
        (Call::GetStatus, 1),
        (Call::GetRealStatus, 2),
        (Call::GetIntegerStatus, 1),
        (Call::GetBooleanStatus, 2),
        (Call::GetStringStatus, 1),
    ];
    pick(rng, &W)
}
