#include "gvins/rtcm/message_types.hpp"

#include "ssr_layout.hpp"

namespace gvins::rtcm {

std::optional<MsmKind> msmKind(int type) {
  if (type < 1071 || type > 1137) return std::nullopt;
  const int group = (type - 1070) / 10;  // 0 GPS, 1 GLONASS, 2 Galileo, 3 SBAS, 4 QZSS, 5 BeiDou, 6 NavIC
  const int msm = (type - 1070) % 10;
  if (msm < 1 || msm > 7) return std::nullopt;
  static constexpr System kSystems[] = {System::Gps,  System::Glonass, System::Galileo,
                                        System::Sbas, System::Qzss,    System::BeiDou,
                                        System::Navic};
  return MsmKind{kSystems[group], msm};
}

int msmMessageNumber(System system, int msm) {
  if (msm < 1 || msm > 7) return 0;
  switch (system) {
    case System::Gps: return 1070 + msm;
    case System::Glonass: return 1080 + msm;
    case System::Galileo: return 1090 + msm;
    case System::Sbas: return 1100 + msm;
    case System::Qzss: return 1110 + msm;
    case System::BeiDou: return 1120 + msm;
    case System::Navic: return 1130 + msm;
  }
  return 0;
}

bool isDecodedType(int type) {
  switch (type) {
    case 1001: case 1002: case 1003: case 1004: case 1005: case 1006: case 1007: case 1008:
    case 1009: case 1010: case 1011: case 1012: case 1019: case 1020: case 1033: case 1042:
    case 1044: case 1045: case 1046: case 1230:
      return true;
    default:
      break;
  }
  // SSR of GPS, GLONASS, Galileo, QZSS and BeiDou (SBAS 1252-1257 not decoded).
  if (ssr::messageKind(type)) return true;
  const auto k = msmKind(type);
  return k && k->system != System::Navic;
}

std::string_view messageDescription(int type) {
  if (const auto k = msmKind(type)) {
    static constexpr std::string_view kNames[7][7] = {
        {"GPS MSM1", "GPS MSM2", "GPS MSM3", "GPS MSM4", "GPS MSM5", "GPS MSM6", "GPS MSM7"},
        {"GLONASS MSM1", "GLONASS MSM2", "GLONASS MSM3", "GLONASS MSM4", "GLONASS MSM5",
         "GLONASS MSM6", "GLONASS MSM7"},
        {"Galileo MSM1", "Galileo MSM2", "Galileo MSM3", "Galileo MSM4", "Galileo MSM5",
         "Galileo MSM6", "Galileo MSM7"},
        {"SBAS MSM1", "SBAS MSM2", "SBAS MSM3", "SBAS MSM4", "SBAS MSM5", "SBAS MSM6", "SBAS MSM7"},
        {"QZSS MSM1", "QZSS MSM2", "QZSS MSM3", "QZSS MSM4", "QZSS MSM5", "QZSS MSM6", "QZSS MSM7"},
        {"BeiDou MSM1", "BeiDou MSM2", "BeiDou MSM3", "BeiDou MSM4", "BeiDou MSM5", "BeiDou MSM6",
         "BeiDou MSM7"},
        {"NavIC MSM1", "NavIC MSM2", "NavIC MSM3", "NavIC MSM4", "NavIC MSM5", "NavIC MSM6",
         "NavIC MSM7"}};
    return kNames[(type - 1070) / 10][k->msm - 1];
  }
  switch (type) {
    case 1001: return "GPS L1 observables";
    case 1002: return "GPS extended L1 observables";
    case 1003: return "GPS L1/L2 observables";
    case 1004: return "GPS extended L1/L2 observables";
    case 1005: return "Station antenna reference point";
    case 1006: return "Station antenna reference point with height";
    case 1007: return "Antenna descriptor";
    case 1008: return "Antenna descriptor and serial number";
    case 1009: return "GLONASS L1 observables";
    case 1010: return "GLONASS extended L1 observables";
    case 1011: return "GLONASS L1/L2 observables";
    case 1012: return "GLONASS extended L1/L2 observables";
    case 1013: return "System parameters";
    case 1014: return "Network auxiliary station data";
    case 1015: return "GPS ionospheric correction differences";
    case 1016: return "GPS geometric correction differences";
    case 1017: return "GPS combined geometric and ionospheric corrections";
    case 1019: return "GPS ephemeris";
    case 1020: return "GLONASS ephemeris";
    case 1021: return "Helmert/abridged Molodenski transformation";
    case 1022: return "Molodenski-Badekas transformation";
    case 1023: return "Residuals, ellipsoidal grid representation";
    case 1024: return "Residuals, plane grid representation";
    case 1025: return "Projection parameters (not LCC2SP, OM)";
    case 1026: return "Projection parameters LCC2SP";
    case 1027: return "Projection parameters OM";
    case 1029: return "Unicode text string";
    case 1030: return "GPS network RTK residual";
    case 1031: return "GLONASS network RTK residual";
    case 1032: return "Physical reference station position";
    case 1033: return "Receiver and antenna descriptors";
    case 1034: return "GPS network FKP gradient";
    case 1035: return "GLONASS network FKP gradient";
    case 1037: return "GLONASS ionospheric correction differences";
    case 1038: return "GLONASS geometric correction differences";
    case 1039: return "GLONASS combined geometric and ionospheric corrections";
    case 1041: return "NavIC ephemeris";
    case 1042: return "BeiDou ephemeris";
    case 1044: return "QZSS ephemeris";
    case 1045: return "Galileo F/NAV ephemeris";
    case 1046: return "Galileo I/NAV ephemeris";
    case 1057: return "SSR GPS orbit correction";
    case 1058: return "SSR GPS clock correction";
    case 1059: return "SSR GPS code bias";
    case 1060: return "SSR GPS orbit and clock correction";
    case 1061: return "SSR GPS URA";
    case 1062: return "SSR GPS high-rate clock correction";
    case 1063: return "SSR GLONASS orbit correction";
    case 1064: return "SSR GLONASS clock correction";
    case 1065: return "SSR GLONASS code bias";
    case 1066: return "SSR GLONASS orbit and clock correction";
    case 1067: return "SSR GLONASS URA";
    case 1068: return "SSR GLONASS high-rate clock correction";
    case 1230: return "GLONASS code-phase biases";
    case 1240: return "SSR Galileo orbit correction";
    case 1241: return "SSR Galileo clock correction";
    case 1242: return "SSR Galileo code bias";
    case 1243: return "SSR Galileo orbit and clock correction";
    case 1244: return "SSR Galileo URA";
    case 1245: return "SSR Galileo high-rate clock correction";
    case 1246: return "SSR QZSS orbit correction";
    case 1247: return "SSR QZSS clock correction";
    case 1248: return "SSR QZSS code bias";
    case 1249: return "SSR QZSS orbit and clock correction";
    case 1250: return "SSR QZSS URA";
    case 1251: return "SSR QZSS high-rate clock correction";
    case 1252: return "SSR SBAS orbit correction";
    case 1253: return "SSR SBAS clock correction";
    case 1254: return "SSR SBAS code bias";
    case 1255: return "SSR SBAS orbit and clock correction";
    case 1256: return "SSR SBAS URA";
    case 1257: return "SSR SBAS high-rate clock correction";
    case 1258: return "SSR BeiDou orbit correction";
    case 1259: return "SSR BeiDou clock correction";
    case 1260: return "SSR BeiDou code bias";
    case 1261: return "SSR BeiDou orbit and clock correction";
    case 1262: return "SSR BeiDou URA";
    case 1263: return "SSR BeiDou high-rate clock correction";
    case 1264: return "SSR VTEC ionosphere";
    case 1265: return "SSR GPS phase bias";
    case 1266: return "SSR GLONASS phase bias";
    case 1267: return "SSR Galileo phase bias";
    case 1268: return "SSR QZSS phase bias";
    case 1269: return "SSR SBAS phase bias";
    case 1270: return "SSR BeiDou phase bias";
    case 1300: return "Service CRS";
    case 1301: return "Helmert transformation";
    case 1302: return "RTCM-CRS";
    case 1303: return "BeiDou network RTK residual";
    case 1304: return "Galileo network RTK residual";
    default: break;
  }
  if (type >= 4001 && type <= 4095) return "Proprietary";
  return "Unknown";
}

}  // namespace gvins::rtcm
